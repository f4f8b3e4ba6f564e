#pragma once
// Test harness: runs a real gpubridged process (or the gpubridge CLI) in a temporary directory.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <arpa/inet.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <utility>
#include <string>
#include <thread>
#include <vector>

namespace gpubridge::test {

namespace fs = std::filesystem;

inline fs::path make_temp_dir(const std::string& tag) {
  std::random_device rd;
  // Short names: Unix socket paths are limited to 107 bytes.
  fs::path dir = fs::temp_directory_path() / ("gbd-" + tag.substr(0, 12) + "-" + std::to_string(rd() % 1000000));
  fs::create_directories(dir);
  return dir;
}

struct ProcessResult {
  int exit_code = -1;  // -1: killed by a signal or timed out
  std::string out, err;
  long max_rss_kib = 0;  // peak resident set size of the child
};

// Sets (NAME=VALUE) or removes (NAME=) environment variables in a child before exec.
inline void apply_env(const std::vector<std::string>& env) {
  for (const auto& kv : env) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos) continue;
    if (eq + 1 == kv.size()) ::unsetenv(kv.substr(0, eq).c_str());
    else ::setenv(kv.substr(0, eq).c_str(), kv.substr(eq + 1).c_str(), 1);
  }
}

// In a forked child: stdout and stderr to the given descriptors, the environment changed, argv
// executed (exit 127 when it cannot be). run_as >= 0: switch to that uid (and gid) first.
[[noreturn]] inline void exec_child(const std::vector<std::string>& argv, int out_fd, int err_fd,
                                    const std::vector<std::string>& env, int run_as = -1) {
  ::dup2(out_fd, 1);
  ::dup2(err_fd, 2);
  apply_env(env);
  if (run_as >= 0 && (::setgid(static_cast<gid_t>(run_as)) != 0 || ::setuid(static_cast<uid_t>(run_as)) != 0)) ::_exit(126);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  ::execv(args[0], args.data());
  ::_exit(127);
}

// Runs argv to completion (or kills it after timeout) capturing stdout and stderr.
inline ProcessResult run_process(const std::vector<std::string>& argv, std::chrono::milliseconds timeout = std::chrono::seconds(30),
                                 const std::vector<std::string>& env = {}) {
  int out_pipe[2], err_pipe[2];
  if (::pipe2(out_pipe, O_CLOEXEC) != 0 || ::pipe2(err_pipe, O_CLOEXEC) != 0) return {};
  const pid_t pid = ::fork();
  if (pid == 0) exec_child(argv, out_pipe[1], err_pipe[1], env);
  ::close(out_pipe[1]);
  ::close(err_pipe[1]);
  ProcessResult r;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  pollfd fds[2] = {{out_pipe[0], POLLIN, 0}, {err_pipe[0], POLLIN, 0}};
  int open = 2;
  while (open > 0 && std::chrono::steady_clock::now() < deadline) {
    if (::poll(fds, 2, 100) <= 0) continue;
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP))) continue;
      char buf[4096];
      const ssize_t n = ::read(fds[i].fd, buf, sizeof buf);
      if (n <= 0) {
        ::close(fds[i].fd);
        fds[i].fd = -1;
        --open;
      } else {
        (i == 0 ? r.out : r.err).append(buf, static_cast<std::size_t>(n));
      }
    }
  }
  for (auto& f : fds)
    if (f.fd >= 0) ::close(f.fd);
  int status = 0;
  if (open > 0) ::kill(pid, SIGKILL);
  rusage usage{};
  ::wait4(pid, &status, 0, &usage);
  r.max_rss_kib = usage.ru_maxrss;
  r.exit_code = (open == 0 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
  return r;
}

// A background child process (e.g. `gpubridge play --loop`) that the test signals and then reaps.
class Child {
 public:
  Child() = default;
  Child(const Child&) = delete;
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    if (err_fd_ >= 0) ::close(err_fd_);
  }
  bool start(const std::vector<std::string>& argv, const std::vector<std::string>& env = {}) {
    int err_pipe[2];
    if (::pipe2(err_pipe, O_CLOEXEC) != 0) return false;
    pid_ = ::fork();
    if (pid_ == 0) exec_child(argv, ::open("/dev/null", O_WRONLY), err_pipe[1], env);
    ::close(err_pipe[1]);
    err_fd_ = err_pipe[0];
    ::fcntl(err_fd_, F_SETFL, O_NONBLOCK);
    return pid_ > 0;
  }
  void signal(int sig) {
    if (pid_ > 0) ::kill(pid_, sig);
  }
  // Waits up to `timeout` for the exit; the exit code, or -1 (killed by a signal, or still running
  // after the timeout: then it is killed).
  int wait(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    int status = 0;
    while (pid_ > 0) {
      drain();
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        drain();
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      if (std::chrono::steady_clock::now() > deadline) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, nullptr, 0);
        pid_ = -1;
        return -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return -1;
  }
  const std::string& err() {
    drain();
    return err_;
  }

 private:
  void drain() {
    if (err_fd_ < 0) return;
    char buf[4096];
    ssize_t n;
    while ((n = ::read(err_fd_, buf, sizeof buf)) > 0) err_.append(buf, static_cast<std::size_t>(n));
  }
  pid_t pid_ = -1;
  int err_fd_ = -1;
  std::string err_;
};

// A gpubridged child process. start() waits for its "ready" line.
class Daemon {
 public:
  Daemon() = default;
  Daemon(const Daemon&) = delete;
  ~Daemon() { stop(); }

  // Returns false (with the daemon's stderr in error()) if it did not become ready.
  // env: NAME=VALUE to set, NAME= to remove in the daemon's environment; run_as: a uid to switch
  // to before exec (tests running as root start a daemon of another user).
  bool start(const std::vector<std::string>& args, const std::vector<std::string>& env = {}, int run_as = -1) {
    int out_pipe[2], err_pipe[2];
    if (::pipe2(out_pipe, O_CLOEXEC) != 0 || ::pipe2(err_pipe, O_CLOEXEC) != 0) return false;
    pid_ = ::fork();
    if (pid_ == 0) {
      std::vector<std::string> all{GPUBRIDGED_PATH};
      all.insert(all.end(), args.begin(), args.end());
      exec_child(all, out_pipe[1], err_pipe[1], env, run_as);
    }
    ::close(out_pipe[1]);
    ::close(err_pipe[1]);
    out_fd_ = out_pipe[0];
    err_fd_ = err_pipe[0];
    ::fcntl(err_fd_, F_SETFL, O_NONBLOCK);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    std::string out;
    while (std::chrono::steady_clock::now() < deadline) {
      pollfd p{out_fd_, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      char buf[512];
      const ssize_t n = ::read(out_fd_, buf, sizeof buf);
      if (n <= 0) break;
      out.append(buf, static_cast<std::size_t>(n));
      if (out.find("ready\n") != std::string::npos) {
        std::size_t pos = 0;
        while ((pos = out.find("listening on ", pos)) != std::string::npos) {
          const auto end = out.find('\n', pos);
          endpoints_.push_back(out.substr(pos + 13, end - pos - 13));
          pos = end;
        }
        return true;
      }
    }
    drain_stderr();
    return false;
  }

  // Sends SIGTERM and waits; returns the exit code (-1 if it had to be killed after `timeout`).
  int terminate(std::chrono::milliseconds timeout = std::chrono::seconds(5)) {
    if (pid_ <= 0) return exit_code_;
    ::kill(pid_, SIGTERM);
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        drain_stderr();
        return exit_code_;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    exit_code_ = -1;
    return exit_code_;
  }
  // Whether the process has exited (reaps it then; exit_code() tells how).
  bool has_exited() {
    if (pid_ <= 0) return true;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) != pid_) return false;
    pid_ = -1;
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return true;
  }
  int exit_code() const { return exit_code_; }
  // SIGKILL and reap (a daemon that failed a test must not keep growing).
  void kill_now() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
  // Open file descriptors (sockets, files) of the process.
  long fd_count() const {
    std::error_code ec;
    long n = 0;
    for (auto it = fs::directory_iterator("/proc/" + std::to_string(pid_) + "/fd", ec); !ec && it != fs::directory_iterator();
         it.increment(ec))
      ++n;
    return ec ? -1 : n;
  }
  // Everything the daemon wrote to stderr so far.
  const std::string& stderr_text() {
    drain_stderr();
    return err_;
  }

  void stop() {
    if (pid_ > 0) terminate();
    if (out_fd_ >= 0) ::close(out_fd_);
    if (err_fd_ >= 0) ::close(err_fd_);
    out_fd_ = err_fd_ = -1;
  }

  pid_t pid() const { return pid_; }
  const std::vector<std::string>& endpoints() const { return endpoints_; }
  std::string error() {
    drain_stderr();
    return err_;
  }

  // Resident set size in KiB from /proc/PID/status.
  long rss_kib() const {
    std::ifstream in("/proc/" + std::to_string(pid_) + "/status");
    std::string line;
    while (std::getline(in, line))
      if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
    return -1;
  }

 private:
  void drain_stderr() {
    if (err_fd_ < 0) return;
    char buf[4096];
    ssize_t n;
    while ((n = ::read(err_fd_, buf, sizeof buf)) > 0) err_.append(buf, static_cast<std::size_t>(n));
  }
  pid_t pid_ = -1;
  int out_fd_ = -1, err_fd_ = -1;
  int exit_code_ = -1;
  std::string err_;
  std::vector<std::string> endpoints_;
};

// A raw Unix-socket connection for misbehaving clients.
class RawSocket {
 public:
  explicit RawSocket(const std::string& path) {
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un sa{};
    sa.sun_family = AF_UNIX;
    std::strncpy(sa.sun_path, path.c_str(), sizeof sa.sun_path - 1);
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  // Loopback TCP.
  RawSocket(const std::string& host, std::uint16_t port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_port = htons(port);
    ::inet_pton(AF_INET, host.c_str(), &sa.sin_addr);
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  RawSocket(RawSocket&& o) noexcept : fd_(std::exchange(o.fd_, -1)) {}
  RawSocket(const RawSocket&) = delete;
  ~RawSocket() {
    if (fd_ >= 0) ::close(fd_);
  }
  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  bool ok() const { return fd_ >= 0; }
  // Sends what the socket takes without blocking; returns the bytes sent (a flooding client that
  // never reads must not block the test once the daemon stops reading).
  std::size_t send_some(const std::vector<std::uint8_t>& b, std::size_t from = 0) {
    std::size_t done = from;
    while (done < b.size()) {
      const ssize_t n = ::send(fd_, b.data() + done, b.size() - done, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
    return done - from;
  }
  // Bytes readable without blocking are read and discarded; false once the peer closed.
  bool drain() {
    std::uint8_t buf[65536];
    for (;;) {
      const ssize_t n = ::recv(fd_, buf, sizeof buf, MSG_DONTWAIT);
      if (n > 0) continue;
      return n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);
    }
  }
  bool send(const std::vector<std::uint8_t>& b) { return ::send(fd_, b.data(), b.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(b.size()); }
  bool send(const std::string& s) { return ::send(fd_, s.data(), s.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(s.size()); }
  // Reads until EOF or timeout; returns the bytes and whether EOF was seen.
  std::pair<std::vector<std::uint8_t>, bool> read_until_closed(std::chrono::milliseconds timeout) {
    std::vector<std::uint8_t> all;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      std::uint8_t buf[4096];
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) return {all, true};
      all.insert(all.end(), buf, buf + n);
    }
    return {all, false};
  }
  int fd() const { return fd_; }

 private:
  int fd_ = -1;
};

}  // namespace gpubridge::test
