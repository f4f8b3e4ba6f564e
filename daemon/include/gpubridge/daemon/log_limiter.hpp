#pragma once
// LogLimiter: one log line per second at most for a recurring event (refused connections): the
// first occurrence of a second is logged as it is, the rest are counted and summed up in the next
// line. A flood of 200,000 refusals costs a handful of lines, not 200,000.
#include <chrono>
#include <cstdint>
#include <string>

#include <spdlog/common.h>

namespace gpubridge::daemon {

class LogLimiter {
 public:
  explicit LogLimiter(spdlog::level::level_enum level) : level_(level) {}
  void note(const std::string& what);

 private:
  spdlog::level::level_enum level_;
  std::chrono::steady_clock::time_point last_{};
  std::uint64_t suppressed_ = 0;
};

}  // namespace gpubridge::daemon
