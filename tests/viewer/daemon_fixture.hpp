#pragma once
// Shared by the viewer tests that run a real gpubridged: start it and wait until it answers, and wait
// until a viewer has subscribed. Needs GPUBRIDGED_PATH and GPUBRIDGE_CLI_PATH from CMake.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "process.hpp"

namespace gpubridge::viewer::test {

// gpubridged listening on `socket` with `args`; fails the test if it does not answer within 10 s.
inline std::unique_ptr<BackgroundProcess> start_daemon(const std::string& socket, const std::vector<std::string>& args,
                                                       const std::filesystem::path& log_dir, const std::string& name) {
  std::vector<std::string> argv{GPUBRIDGED_PATH, "--listen", socket, "--foreground"};
  argv.insert(argv.end(), args.begin(), args.end());
  auto d = std::make_unique<BackgroundProcess>(argv, std::vector<std::string>{}, log_dir, name);
  for (int i = 0; i < 200; ++i) {  // up to 10 s for the socket to accept
    if (run_process({GPUBRIDGE_CLI_PATH, "status", "--connect", socket}).exit_code == 0) return d;
    if (!d->running()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ADD_FAILURE() << "gpubridged did not come up: " << d->log();
  return d;
}

// True once the daemon on `socket` lists a subscribed gpubridge-view session.
inline bool viewer_subscribed(const std::string& socket) {
  const auto r = run_process({GPUBRIDGE_CLI_PATH, "--json", "status", "--connect", socket});
  if (r.exit_code != 0) return false;
  const auto j = nlohmann::json::parse(r.out, nullptr, false);
  if (j.is_discarded() || !j.contains("clients")) return false;
  for (const auto& c : j["clients"])
    if (c.value("name", "") == "gpubridge-view" && c.value("subscribed", false)) return true;
  return false;
}

inline ::testing::AssertionResult wait_subscribed(BackgroundProcess& viewer, const std::string& socket) {
  for (int i = 0; i < 300; ++i) {  // up to 15 s
    if (viewer_subscribed(socket)) return ::testing::AssertionSuccess();
    if (!viewer.running()) return ::testing::AssertionFailure() << "viewer exited: " << viewer.log();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return ::testing::AssertionFailure() << "viewer never subscribed: " << viewer.log();
}

}  // namespace gpubridge::viewer::test
