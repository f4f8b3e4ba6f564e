#include "gpubridge/viewer/rate_meter.hpp"

namespace gpubridge::viewer {

namespace {
constexpr std::size_t kMaxSamples = 4096;  // a window never needs more than this at display rates
}

void RateMeter::sample(std::uint64_t now_ns, std::uint64_t cumulative) {
  if (!samples_.empty() && (now_ns < samples_.back().t_ns || cumulative < samples_.back().count)) {
    samples_.clear();  // clock or counter went backwards (new source): start over
  }
  samples_.push_back({now_ns, cumulative});
  // Keep one sample at or before the window start so the rate spans the whole window.
  while (samples_.size() > 2 && now_ns - samples_[1].t_ns >= window_ns_) samples_.pop_front();
  while (samples_.size() > kMaxSamples) samples_.pop_front();
}

double RateMeter::rate() const {
  if (samples_.size() < 2) return 0.0;
  const auto& a = samples_.front();
  const auto& b = samples_.back();
  if (b.t_ns == a.t_ns) return 0.0;
  return static_cast<double>(b.count - a.count) * 1e9 / static_cast<double>(b.t_ns - a.t_ns);
}

}  // namespace gpubridge::viewer
