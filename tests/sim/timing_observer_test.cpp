// The timing model's formulas (docs/protocol.md section 19) on hand-computed counters, the
// attribute observer behind `render --dump-attributes` (the preview path's error bounds: preview_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "gpubridge/sim/timing.hpp"
#include "reference.hpp"
#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

TEST(SimTiming, FormulasOnHandComputedCounters) {
  DeviceStats w;
  w.frames_received = 20;
  w.queued_executed = 10;
  w.triangles_rasterised = 2;
  w.pixels_scanned = 100;
  w.pixels_covered = 60;
  w.pixels_depth_passed = 50;
  w.clear_bytes = 800;
  const BoardTiming b;  // defaults of section 19
  const TimingEstimate e = estimate_timing(w, b, 4);
  // pipeline = 10·1 + 2·24 + 100·0.25 + 50·1 + 800/8 = 233
  EXPECT_DOUBLE_EQ(e.pipeline_cycles, 233.0);
  // bytes = 8·60 + 4·50 + 800 = 1480 → 370 cycles at 4 bytes/cycle
  EXPECT_EQ(e.memory_bytes, 1480u);
  EXPECT_DOUBLE_EQ(e.board_cycles, 370.0);
  EXPECT_NEAR(e.board_ms, 370.0 / 50e3, 1e-12);
  // SPI: 20·72 bits at 40 MHz + one CS gap of 1 µs
  EXPECT_NEAR(e.spi_ms, 20 * 72 / 40e3 + 1e-3, 1e-12);
  EXPECT_NEAR(e.frame_ms, e.spi_ms, 1e-12);
  // Without a depth buffer (painter's order) covered pixels move no depth bytes: 200 + 800.
  EXPECT_EQ(estimate_timing(w, b, 4, /*depth_buffer=*/false).memory_bytes, 1000u);
  BoardTiming slow;
  ASSERT_TRUE(apply_timing_setting(slow, "clock_mhz=0.01").ok());
  EXPECT_GT(estimate_timing(w, slow, 4).frame_ms, e.frame_ms);
  EXPECT_FALSE(apply_timing_setting(slow, "clock_mhz=0").ok());
  EXPECT_FALSE(apply_timing_setting(slow, "clock_mhz=nan").ok());
  EXPECT_FALSE(apply_timing_setting(slow, "nosuch=1").ok());
}

// The gateware profiles' presets (fitted on the RTL, docs/gateware.md): profile=NAME replaces every
// value, later settings still apply, and an unknown name says which ones exist.
TEST(SimTiming, GatewarePresetsReplaceTheProfile) {
  BoardTiming b;
  ASSERT_TRUE(apply_timing_setting(b, "profile=up5k").ok());
  EXPECT_EQ(b.name, "up5k");
  EXPECT_DOUBLE_EQ(b.clock_mhz, 25.125);
  EXPECT_DOUBLE_EQ(b.spi_clock_mhz, 7.5);
  // the bit-serial setup of Gouraud + Z (docs/gateware.md: 1,289 cycles on the RTL's core bench)
  EXPECT_GT(b.setup_cycles[3], 1200.0);
  EXPECT_LT(b.setup_cycles[3], 1400.0);
  EXPECT_DOUBLE_EQ(b.setup_cycles[4], 0.0);  // no texture unit
  EXPECT_FALSE(b.memory_bound);
  ASSERT_TRUE(apply_timing_setting(b, "clock_mhz=25").ok());
  EXPECT_DOUBLE_EQ(b.clock_mhz, 25.0);
  ASSERT_TRUE(apply_timing_setting(b, "profile=ecp5").ok());
  EXPECT_EQ(b.name, "ecp5");
  EXPECT_DOUBLE_EQ(b.memory_bytes_per_cycle, 2.0);  // 16-bit SDR SDRAM
  EXPECT_GT(b.setup_cycles[7], b.setup_cycles[0]);  // textured Gouraud + Z sets up 8 planes, flat none
  EXPECT_GT(b.setup_cycles[7], 250.0);               // 336 cycles on the core bench
  ASSERT_TRUE(apply_timing_setting(b, "profile=ecp5-50mhz").ok());
  EXPECT_DOUBLE_EQ(b.cycles_per_triangle, BoardTiming{}.cycles_per_triangle);
  EXPECT_DOUBLE_EQ(b.setup_cycles[7], 0.0);
  EXPECT_TRUE(b.memory_bound);
  const auto bad = apply_timing_setting(b, "profile=ice40");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("up5k"), std::string::npos) << bad.error().message;
}

TEST(SimObserver, ReportsEveryCoveredPixelWithExactValues) {
  Canvas c(40, 30);
  std::vector<CoveredPixel> seen;
  c.dev->set_pixel_observer([&](const CoveredPixel& p) { seen.push_back(p); });
  w(*c.dev, Reg::TRI_MODE, 1);
  const ref::P p0{13, 21}, p1{600, 77}, p2{250, 460};
  c.tri(13, 21, 600, 77, 250, 460, 0x00FF8020, 0x40FF8020, 0xFFFF8020, 100, 200, 700);
  c.dev->set_pixel_observer(nullptr);
  std::size_t expected = 0;
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) expected += ref::sample(p0, p1, p2, x, y).covered;
  ASSERT_EQ(seen.size(), expected);
  for (const auto& p : seen) {
    const ref::Bary s = ref::sample(p0, p1, p2, p.x, p.y);
    ASSERT_TRUE(s.covered);
    EXPECT_EQ(p.triangle, 0u);
    EXPECT_EQ(p.g, 255.0);  // constant attributes are exact
    EXPECT_EQ(p.b, 128.0);
    EXPECT_GE(p.r, 0.0);
    EXPECT_LE(p.r, 255.0);
    // The rounded value the framebuffer holds is the observer's value rounded half up.
    EXPECT_EQ(static_cast<unsigned>(std::floor(p.r + 0.5)), c.rgba(p.x, p.y) >> 24);
    EXPECT_GE(p.z, 100.0);
    EXPECT_LE(p.z, 700.0);
  }
}

}  // namespace
}  // namespace gpubridge::sim::test
