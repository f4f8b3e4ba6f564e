// The best-frame rule every timed side of `gpubridge bench accuracy` uses (bench/src/best_frame.hpp).
#include <gtest/gtest.h>

#include <vector>

#include "best_frame.hpp"

namespace gpubridge::bench {
namespace {

// A frame source with scripted durations; records how many frames were asked for.
struct Script {
  std::vector<double> seconds;
  unsigned calls = 0;
  double operator()() { return seconds[std::min<std::size_t>(calls++, seconds.size() - 1)]; }
};

TEST(BestFrame, TakesTheCountAfterAWarmUpWithoutAWindow) {
  Script s{{0.001, 0.5, 0.3, 0.4, 0.2, 0.6, 0.05}};  // the warm-up's 1 ms must not count
  EXPECT_DOUBLE_EQ(best_frame_seconds({.runs = 5, .min_seconds = 0}, std::ref(s)), 0.2);
  EXPECT_EQ(s.calls, 6u);
}

TEST(BestFrame, KeepsTimingUntilTheWindowIsFull) {
  // 10 ms frames in a 100 ms window: ten timed frames after the warm-up, though the count asks for 2;
  // the quiet frame (4 ms) comes eighth.
  Script s{{0.010, 0.010, 0.010, 0.010, 0.010, 0.010, 0.010, 0.010, 0.004, 0.010}};
  EXPECT_DOUBLE_EQ(best_frame_seconds({.runs = 2, .min_seconds = 0.1}, std::ref(s)), 0.004);
  EXPECT_GE(s.calls, 1u + 10u);
  EXPECT_LE(s.calls, 1u + 12u);  // 8 frames of 10 ms + one of 4 + two more to pass 100 ms
}

TEST(BestFrame, LongFramesStopAtTheCount) {
  Script s{{1.0}};
  EXPECT_DOUBLE_EQ(best_frame_seconds({.runs = 3, .min_seconds = 0.25}, std::ref(s)), 1.0);
  EXPECT_EQ(s.calls, 4u);
}

TEST(BestFrame, FramesOfNoTimeStopAtTheCap) {
  Script s{{0.0}};
  (void)best_frame_seconds({.runs = 1, .min_seconds = 1.0}, std::ref(s));
  EXPECT_EQ(s.calls, 1u + kMaxFramesPerMeasurement);
}

}  // namespace
}  // namespace gpubridge::bench
