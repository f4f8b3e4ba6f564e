#pragma once
// Events per second over the last second, from samples of a cumulative counter.
#include <cstdint>
#include <deque>

namespace gpubridge::viewer {

class RateMeter {
 public:
  explicit RateMeter(std::uint64_t window_ns = 1'000'000'000) : window_ns_(window_ns) {}
  // Records that `cumulative` events had happened by time `now_ns` (monotonic, non-decreasing).
  void sample(std::uint64_t now_ns, std::uint64_t cumulative);
  // Events per second between the oldest sample inside the window and the newest; 0 with fewer
  // than two samples.
  double rate() const;

 private:
  struct Sample { std::uint64_t t_ns, count; };
  std::uint64_t window_ns_;
  std::deque<Sample> samples_;  // bounded: samples older than the window are dropped (kept: 1)
};

}  // namespace gpubridge::viewer
