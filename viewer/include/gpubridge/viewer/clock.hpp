#pragma once
// The clock FRAME messages stamp swaps with: CLOCK_MONOTONIC in nanoseconds. The daemon and the
// viewer on the same machine read the same clock, so their difference is the display latency.
#include <cstdint>
#include <ctime>

namespace gpubridge::viewer {

inline std::uint64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000u + static_cast<std::uint64_t>(ts.tv_nsec);
}

}  // namespace gpubridge::viewer
