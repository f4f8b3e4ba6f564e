// The timing model's structure (the golden streams check its figures against the RTL).
#include <gtest/gtest.h>

#include "gpubridge/dmc1/command.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "golden_data.hpp"

namespace gpubridge::dmc1 {
namespace {

std::vector<std::uint64_t> frame_of(std::uint64_t span_word, unsigned frames = 1) {
  std::vector<std::uint64_t> s;
  for (unsigned c = 0; c < kColumns * frames; ++c) {
    s.push_back(span_word);
    s.push_back(end_of_column());
  }
  return s;
}

std::vector<std::uint64_t> cycles_of(const std::vector<std::uint64_t>& words, TimingParameters p = {}) {
  DeviceOptions o;
  o.timing = p;
  auto dev = Device::create(o, test::golden_textures(), test::golden_palette());
  EXPECT_TRUE(dev.ok());
  (*dev)->submit(words);
  return (*dev)->timing().frame_cycles();
}

TEST(Timing, ShortColumnsWaitForTheColumnSender) {
  // A one-row background per column draws in a few cycles: the sender (241 words + pipeline) sets the pace.
  const TimingParameters p;
  const auto c = cycles_of(frame_of(wall({0, 0, 15, 0}, 0xFFFF, 0, 0)));
  ASSERT_EQ(c.size(), 1u);
  EXPECT_GE(c[0], std::uint64_t{kColumns} * p.column_send());
  EXPECT_LT(c[0], std::uint64_t{kColumns} * (p.column_send() + 10) + p.startup);
}

TEST(Timing, LongColumnsAreDrawerBound) {
  // A full-height textured wall: 242 events of 7 cycles per column, the sender hidden behind it.
  const TimingParameters p;
  const auto c = cycles_of(frame_of(wall({0, 239, 15, 5}, 0x100, 0, 0)));
  ASSERT_EQ(c.size(), 1u);
  const std::uint64_t drawing = std::uint64_t{kColumns} * 242 * p.texel_period;
  EXPECT_GT(c[0], drawing);
  EXPECT_LT(c[0], drawing + kColumns * (p.span_overhead + p.bind + p.end_of_column) + p.startup + p.column_send() + 1);
}

TEST(Timing, OnlyTheFirstFrameIncludesStartUp) {
  const auto c = cycles_of(frame_of(wall({0, 239, 15, 0}, 0xFFFF, 0, 0), 3));
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[1], c[2]);
  EXPECT_GT(c[0], c[1]);
}

TEST(Timing, TheSpiScreenInTheLoopIsScreenBound) {
  // The sheet: 320 * 240 * 19 = 1,459,200 cycles with the real SPI screen controller, for a frame
  // whose columns draw faster than the screen takes them (a background per column here; the
  // golden "mixed" stream has columns that draw longer than that).
  TimingParameters p;
  p.screen_cycles_per_word = 19;
  const auto c = cycles_of(frame_of(wall({0, 239, 15, 0}, 0xFFFF, 0, 0)), p);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_NEAR(static_cast<double>(c[0]), 1459200.0, 0.01 * 1459200.0);
  const auto heavy = cycles_of(test::golden_stream("mixed"), p);
  EXPECT_GT(heavy[0], c[0]);
}

TEST(Timing, SettingsAreCheckedAndNamed) {
  TimingParameters p;
  EXPECT_TRUE(apply_timing_setting(p, "screen_cycles_per_word=19").ok());
  EXPECT_EQ(p.screen_cycles_per_word, 19u);
  EXPECT_TRUE(apply_timing_setting(p, "clock_mhz=33").ok());
  EXPECT_EQ(p.clock_mhz, 33.0);
  for (const char* bad : {"clock_mhz=0", "clock_mhz=nan", "texel_period=-1", "texel_period=7x", "bind", "warp=9"}) {
    auto r = apply_timing_setting(p, bad);
    EXPECT_FALSE(r.ok()) << bad;
  }
  auto unknown = apply_timing_setting(p, "warp=9");
  EXPECT_NE(unknown.error().message.find("texel_period"), std::string::npos) << unknown.error().message;
}

}  // namespace
}  // namespace gpubridge::dmc1
