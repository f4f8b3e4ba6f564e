#pragma once
// A gpubridged child process for the daemon benchmarks (bench daemon, bench remote): started with
// the given arguments, its "listening on" endpoints read from stdout, stopped with SIGTERM.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"

namespace gpubridge::cli {

// A gpubridged child; stopped with SIGTERM.
class DaemonChild {
 public:
  ~DaemonChild() { stop(); }
  Result<std::vector<std::string>> start(const std::string& exe, const std::vector<std::string>& args) {
    int out[2];
    if (::pipe2(out, O_CLOEXEC) != 0) return make_error("pipe failed");
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], 1);
      const int devnull = ::open("/dev/null", O_WRONLY);
      if (devnull >= 0) ::dup2(devnull, 2);
      std::vector<std::string> all{exe};
      all.insert(all.end(), args.begin(), args.end());
      std::vector<char*> argv;
      for (auto& a : all) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execvp(exe.c_str(), argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    std::string text;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (std::chrono::steady_clock::now() < deadline && text.find("ready\n") == std::string::npos) {
      pollfd p{out[0], POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      char buf[512];
      const ssize_t n = ::read(out[0], buf, sizeof buf);
      if (n <= 0) break;
      text.append(buf, static_cast<std::size_t>(n));
    }
    ::close(out[0]);
    if (text.find("ready\n") == std::string::npos) return make_error("gpubridged (" + exe + ") did not start");
    std::vector<std::string> endpoints;
    for (std::size_t pos = 0; (pos = text.find("listening on ", pos)) != std::string::npos;) {
      const auto end = text.find('\n', pos);
      endpoints.push_back(text.substr(pos + 13, end - pos - 13));
      pos = end;
    }
    return endpoints;
  }
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
};

// The gpubridged next to this gpubridge (build tree or install), else the one on PATH.
inline std::string find_daemon(const std::string& given) {
  if (!given.empty()) return given;
  std::error_code ec;
  namespace fs = std::filesystem;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  for (const fs::path& p : {self.parent_path() / "gpubridged", self.parent_path() / ".." / "daemon" / "gpubridged",
                            self.parent_path() / ".." / "sbin" / "gpubridged"})
    if (fs::exists(p, ec)) return p.string();
  return "gpubridged";
}


}  // namespace gpubridge::cli
