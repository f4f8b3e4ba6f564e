#include "shell.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

namespace gpubridge::readme {
namespace {

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Child side: own process group (so a timeout can end everything the line started), environment,
// working directory, redirections, then the shell. Never returns.
[[noreturn]] void exec_shell(const std::string& line, const ShellEnv& env, const std::string& out_path,
                             const std::string& err_path) {
  setpgid(0, 0);
  for (const auto& name : env.unset) unsetenv(name.c_str());
  for (const auto& [name, value] : env.set) setenv(name.c_str(), value.c_str(), 1);
  const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  const int null = open("/dev/null", O_RDONLY);
  if (out < 0 || err < 0 || null < 0 || chdir(env.cwd.c_str()) != 0) _exit(126);
  dup2(null, 0);
  dup2(out, 1);
  dup2(err, 2);
  execl("/bin/sh", "sh", "-c", line.c_str(), static_cast<char*>(nullptr));
  _exit(127);
}

constexpr auto kPoll = std::chrono::milliseconds(10);

}  // namespace

std::string Outcome::status() const {
  if (timed_out) return "did not finish in time (killed)";
  if (signal) return "killed by signal " + std::to_string(signal) + " (" + strsignal(signal) + ")";
  return "exit status " + std::to_string(exit_code);
}

Outcome run_shell(const std::string& line, const ShellEnv& env, const std::filesystem::path& log_dir,
                  const std::string& name, std::chrono::milliseconds limit) {
  ShellJob job(line, env, log_dir, name);
  if (auto done = job.wait(limit)) return *done;
  Outcome o = job.stop(SIGKILL, std::chrono::seconds(5));
  o.timed_out = true;
  return o;
}

ShellJob::ShellJob(const std::string& line, const ShellEnv& env, const std::filesystem::path& log_dir,
                   const std::string& name)
    : out_path_(log_dir / (name + ".out")), err_path_(log_dir / (name + ".err")) {
  pid_ = fork();
  if (pid_ == 0) exec_shell(line, env, out_path_.string(), err_path_.string());
  if (pid_ > 0) setpgid(pid_, pid_);  // also here: no race with the first signal
}

ShellJob::~ShellJob() {
  if (pid_ > 0 && !done_) {
    kill(-pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

Outcome ShellJob::finished(int wait_status) const {
  Outcome o;
  if (WIFEXITED(wait_status)) o.exit_code = WEXITSTATUS(wait_status);
  if (WIFSIGNALED(wait_status)) o.signal = WTERMSIG(wait_status);
  o.out = read_file(out_path_);
  o.err = read_file(err_path_);
  return o;
}

bool ShellJob::running() { return !wait(std::chrono::milliseconds(0)); }

std::optional<Outcome> ShellJob::wait(std::chrono::milliseconds limit) {
  if (done_) return done_;
  if (pid_ <= 0) {
    Outcome o;
    o.err = "fork failed";
    done_ = o;
    return done_;
  }
  const auto deadline = std::chrono::steady_clock::now() + limit;
  for (;;) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      done_ = finished(status);
      // Whatever the line left behind in its process group goes with it.
      kill(-pid_, SIGKILL);
      return done_;
    }
    if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(kPoll);
  }
}

Outcome ShellJob::stop(int signal, std::chrono::milliseconds limit) {
  if (done_) return *done_;
  kill(pid_, signal);
  if (auto o = wait(limit)) return *o;
  kill(-pid_, SIGKILL);
  int status = 0;
  waitpid(pid_, &status, 0);
  done_ = finished(status);
  done_->timed_out = true;
  return *done_;
}

std::string ShellJob::out() const { return read_file(out_path_); }
std::string ShellJob::err() const { return read_file(err_path_); }

}  // namespace gpubridge::readme
