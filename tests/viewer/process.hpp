#pragma once
// Test helpers: run the real executables as child processes (exit code, stdout, stderr, time
// limit) and start a private Xvfb server.
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <sys/types.h>

namespace gpubridge::viewer::test {

struct ProcessResult {
  int exit_code = -1;  // -1: killed after the time limit (or by a signal)
  std::string out, err;
};

// env entries are "NAME=value" added to (or replacing in) this process's environment; an entry
// "NAME=" with an empty value removes NAME.
ProcessResult run_process(const std::vector<std::string>& argv, const std::vector<std::string>& env = {},
                          std::chrono::milliseconds limit = std::chrono::seconds(60));

// A child running in the background (stdout/stderr to files in dir); killed by the destructor.
class BackgroundProcess {
 public:
  BackgroundProcess(const std::vector<std::string>& argv, const std::vector<std::string>& env,
                    const std::filesystem::path& log_dir, const std::string& name);
  BackgroundProcess(const BackgroundProcess&) = delete;
  BackgroundProcess& operator=(const BackgroundProcess&) = delete;
  ~BackgroundProcess();
  bool running();
  // Waits up to `limit` for the process to exit: its exit code, or nullopt if still running.
  std::optional<int> wait_exit(std::chrono::milliseconds limit);
  void kill_and_wait(int signal);
  std::string output() const;  // its stdout so far
  std::string log() const;  // its stderr so far
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  std::filesystem::path err_path_, out_path_;
};

// A private X server for the GL tests. display() is empty when Xvfb could not be started
// (reason() says why).
class Xvfb {
 public:
  Xvfb();
  ~Xvfb();
  const std::string& display() const { return display_; }
  const std::string& reason() const { return reason_; }

 private:
  pid_t pid_ = -1;
  std::string display_, reason_;
};

// A fresh temporary directory, removed by the destructor.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace gpubridge::viewer::test
