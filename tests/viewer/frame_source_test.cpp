// The newest-only mailbox: stale frames are dropped and counted, bad frames refused, waiting
// wakes on frames and status changes, and the test pattern source streams.
#include <gtest/gtest.h>

#include <atomic>
#include <latch>

#include "gpubridge/viewer/test_frame_source.hpp"

namespace gpubridge::viewer {
namespace {

using namespace std::chrono_literals;

// A source driven by the test: run() publishes what the test hands it, then idles.
class ScriptedSource final : public FrameSource {
 public:
  ~ScriptedSource() override { stop(); }
  void push(Frame f) { publish_frame(std::move(f)); }
  void set(SourceStatus s) { publish_status(std::move(s)); }

 private:
  void run(std::stop_token stop) override {
    while (sleep_for(stop, 10ms)) {
    }
  }
};

Frame frame_number(std::uint32_t n) {
  return make_test_frame(TestPatternSpec{4, 4, protocol::PixelFormat::RGBA8888, 60}, n, 0);
}

TEST(FrameSource, KeepsOnlyTheNewestFrame) {
  ScriptedSource s;
  for (std::uint32_t n = 1; n <= 5; ++n) s.push(frame_number(n));
  auto f = s.take_newest();
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->number, 5u);
  EXPECT_FALSE(s.take_newest().has_value());
  const auto c = s.counters();
  EXPECT_EQ(c.received, 5u);
  EXPECT_EQ(c.dropped, 4u);
  EXPECT_EQ(c.taken, 1u);
}

TEST(FrameSource, RefusesInconsistentFramesAndSaysWhy) {
  ScriptedSource s;
  Frame bad = frame_number(9);
  bad.width = 2000;
  s.push(bad);
  EXPECT_FALSE(s.take_newest().has_value());
  const auto c = s.counters();
  EXPECT_EQ(c.rejected, 1u);
  EXPECT_NE(c.last_rejection.find("frame 9"), std::string::npos);
}

TEST(FrameSource, WaitWakesOnFrameAndOnStatusChange) {
  ScriptedSource s;
  const auto v0 = s.status_version();
  EXPECT_FALSE(s.wait(1ms, v0));
  SourceStatus st;
  st.state = SourceStatus::State::Waiting;
  st.address = "unix:/nowhere";
  s.set(st);
  EXPECT_TRUE(s.wait(0ms, v0));
  EXPECT_EQ(s.status().state, SourceStatus::State::Waiting);
  const auto v1 = s.status_version();
  EXPECT_FALSE(s.wait(1ms, v1));
  s.push(frame_number(1));
  EXPECT_TRUE(s.wait(0ms, v1));
}

TEST(FrameSource, CallsTheChangeCallbackFromTheProducer) {
  ScriptedSource s;
  std::atomic<int> calls{0};
  s.start([&] { ++calls; });
  s.push(frame_number(1));
  s.set(SourceStatus{});
  EXPECT_EQ(calls.load(), 2);
  s.stop();
  s.stop();  // idempotent
}

TEST(TestFrameSource, StreamsIncreasingFrameNumbersUntilStopped) {
  TestFrameSource s(TestPatternSpec{16, 8, protocol::PixelFormat::RGB565, 200});
  s.start();
  std::optional<std::uint32_t> last;
  int got = 0;
  for (int i = 0; i < 400 && got < 3; ++i) {
    if (!s.wait(50ms, s.status_version())) continue;
    if (auto f = s.take_newest()) {
      if (last) {
        EXPECT_GT(f->number, *last);
      }
      last = f->number;
      EXPECT_EQ(f->width, 16u);
      EXPECT_EQ(f->format, protocol::PixelFormat::RGB565);
      ++got;
    }
  }
  EXPECT_EQ(got, 3);
  EXPECT_EQ(s.status().state, SourceStatus::State::Streaming);
  s.stop();
}

}  // namespace
}  // namespace gpubridge::viewer
