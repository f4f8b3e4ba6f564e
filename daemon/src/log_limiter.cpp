#include "gpubridge/daemon/log_limiter.hpp"

#include "gpubridge/common/log.hpp"

namespace gpubridge::daemon {

void LogLimiter::note(const std::string& what) {
  const auto now = std::chrono::steady_clock::now();
  if (last_ != std::chrono::steady_clock::time_point{} && now - last_ < std::chrono::seconds(1)) {
    ++suppressed_;
    return;
  }
  if (suppressed_)
    logger("daemon")->log(level_, "{} (and {} more like it since the previous such line)", what, suppressed_);
  else
    logger("daemon")->log(level_, "{}", what);
  suppressed_ = 0;
  last_ = now;
}

}  // namespace gpubridge::daemon
