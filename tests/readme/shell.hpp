#pragma once
// Running documented command lines the way a user's shell does: `/bin/sh -c LINE` in a working
// directory with a given environment, stdin from /dev/null, stdout and stderr kept in files.
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace gpubridge::readme {

struct ShellEnv {
  std::filesystem::path cwd;
  std::vector<std::pair<std::string, std::string>> set;  // NAME, value
  std::vector<std::string> unset;
};

struct Outcome {
  int exit_code = -1;  // when the process exited
  int signal = 0;      // when a signal ended it
  bool timed_out = false;
  std::string out, err;
  std::string status() const;  // "exit status 3", "killed by signal 15", "still running after 60 s"
};

// Runs `line` with /bin/sh -c and waits up to `limit` (then kills the process group).
Outcome run_shell(const std::string& line, const ShellEnv& env, const std::filesystem::path& log_dir,
                  const std::string& name, std::chrono::milliseconds limit);

// A line running alongside the following ones (`line &`, or a daemon a user leaves running). The
// shell execs the command, so signals reach the program itself.
class ShellJob {
 public:
  ShellJob(const std::string& line, const ShellEnv& env, const std::filesystem::path& log_dir, const std::string& name);
  ShellJob(const ShellJob&) = delete;
  ShellJob& operator=(const ShellJob&) = delete;
  ~ShellJob();  // kills what is still running

  bool running();
  // Waits up to `limit` for the job to end by itself.
  std::optional<Outcome> wait(std::chrono::milliseconds limit);
  // Sends `signal` and waits up to `limit`; kills it (SIGKILL) after that and says so.
  Outcome stop(int signal, std::chrono::milliseconds limit);
  std::string out() const;
  std::string err() const;

 private:
  Outcome finished(int wait_status) const;
  pid_t pid_ = -1;
  std::filesystem::path out_path_, err_path_;
  std::optional<Outcome> done_;
};

}  // namespace gpubridge::readme
