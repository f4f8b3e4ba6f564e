// The counters behind the gateware-shaped timing terms (docs/protocol.md section 19): triangles,
// bounding-box rows and columns and covered pixels per render-state class, rejected setups,
// clears by rectangle; and the terms of the model that use them.
#include <gtest/gtest.h>

#include "gpubridge/sim/timing.hpp"
#include "reference.hpp"
#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

constexpr unsigned kGouraud = 1, kZTest = 4, kZWrite = 64, kMaskAll = 0xF << 10;
constexpr unsigned kLess = 1 << 3;  // Z_FUNC LESS

// A triangle with its corners on pixel corners: (2, 3), (30, 3), (2, 40) in pixels. Its box holds
// the pixels whose centres lie between the extremes: columns 2..29, rows 3..39.
void draw_probe(Canvas& c) {
  c.tri(2 * 16, 3 * 16, 30 * 16, 3 * 16, 2 * 16, 40 * 16, 0xFF000000, 0x00FF0000, 0x0000FFFF, 10, 20, 30);
}
std::uint64_t probe_covered() {
  std::uint64_t n = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) n += ref::sample({2 * 16, 3 * 16}, {30 * 16, 3 * 16}, {2 * 16, 40 * 16}, x, y).covered;
  return n;
}

TEST(SimTimingCounters, ClearsCountRectanglesRowsAndPixels) {
  Canvas c(64, 48);  // clears colour (4 bytes a pixel) and depth
  const DeviceStats& s = c.dev->stats();
  EXPECT_EQ(s.clears, 2u);
  EXPECT_EQ(s.clear_rows, 2u * 48);
  EXPECT_EQ(s.clear_pixels, 2u * 64 * 48);
  EXPECT_EQ(s.clear_bytes, 2u * 64 * 48 * 4);
  c.dev->reset_stats();
  w(*c.dev, Reg::SCISSOR, scissor(8, 4, 20, 10));
  w(*c.dev, Reg::CLEAR, 0);
  w(*c.dev, Reg::SCISSOR, scissor(8, 4, 8, 10));  // empty: no clear
  w(*c.dev, Reg::CLEAR, 0);
  const DeviceStats& t = c.dev->stats();
  EXPECT_EQ(t.clears, 1u);
  EXPECT_EQ(t.clear_rows, 6u);
  EXPECT_EQ(t.clear_pixels, 12u * 6);
}

TEST(SimTimingCounters, TrianglesRowsColumnsAndPixelsByRenderStateClass) {
  const std::uint64_t covered = probe_covered();
  ASSERT_GT(covered, 400u);
  for (unsigned threads : {1u, 3u}) {
    DeviceOptions o;
    o.threads = threads;
    Canvas c(64, 48, 0, o);
    c.dev->reset_stats();
    w(*c.dev, Reg::TRI_MODE, kGouraud);
    draw_probe(c);
    w(*c.dev, Reg::TRI_MODE, kGouraud | kZTest | kLess | kZWrite);
    draw_probe(c);
    draw_probe(c);
    // colour fully masked: no colour planes, only Z (the write)
    w(*c.dev, Reg::TRI_MODE, kGouraud | kZWrite | kMaskAll);
    draw_probe(c);
    // writes nothing at all: skipped before setup, counted nowhere
    w(*c.dev, Reg::TRI_MODE, kGouraud | kMaskAll);
    draw_probe(c);
    // set up for nothing: D = 0, and a box outside the framebuffer
    w(*c.dev, Reg::TRI_MODE, 0);
    c.tri(0, 0, 160, 160, 320, 320);
    c.tri(80 * 16, 0, 90 * 16, 0, 80 * 16, 10 * 16);
    const DeviceStats& s = c.dev->stats();
    const DeviceStats::ModeWork probe{1, 37, 28, covered};
    EXPECT_TRUE(s.by_mode[1] == probe) << "threads " << threads;                                      // gouraud
    EXPECT_TRUE(s.by_mode[3] == (DeviceStats::ModeWork{2, 74, 56, 2 * covered})) << "threads " << threads;  // gouraud_z
    EXPECT_TRUE(s.by_mode[2] == probe) << "threads " << threads;                                      // z
    EXPECT_EQ(s.by_mode[0].triangles, 0u);
    EXPECT_EQ(s.triangles_rasterised, 4u);
    EXPECT_EQ(s.triangles_rejected, 2u);
    EXPECT_EQ(s.pixels_covered, 4 * covered);
  }
  EXPECT_STREQ(mode_class_name(3), "gouraud_z");
  EXPECT_STREQ(mode_class_name(7), "tex_gouraud_z");
}

// pipeline = the section 19 terms + Σ_class (T·setup + R·row + K·column + P·pixel)
//            + rejected·c + clears·c + clear rows·c + clear pixels·c + MEM_DATA writes·c
TEST(SimTimingCounters, StructureTermsOfTheModel) {
  DeviceStats w;
  w.by_mode[1] = {2, 30, 40, 500};
  w.by_mode[3] = {1, 10, 12, 100};
  w.triangles_rejected = 3;
  w.clears = 2;
  w.clear_rows = 96;
  w.clear_pixels = 6144;
  w.mem_data_writes = 7;
  BoardTiming b;
  b.cycles_per_command = b.cycles_per_triangle = b.cycles_per_scanned_pixel = b.cycles_per_pixel = 0;
  for (const char* s : {"setup_cycles_gouraud=100", "row_cycles_gouraud=3", "column_cycles_gouraud=0.5",
                        "pixel_cycles_gouraud=4", "setup_cycles_gouraud_z=200", "row_cycles_gouraud_z=5",
                        "column_cycles_gouraud_z=1", "pixel_cycles_gouraud_z=5", "cycles_per_rejected_triangle=10",
                        "cycles_per_clear=50", "cycles_per_clear_row=2", "cycles_per_clear_pixel=1",
                        "cycles_per_mem_write=6", "memory_bytes_per_cycle=1e9"})
    ASSERT_TRUE(apply_timing_setting(b, s).ok()) << s;
  EXPECT_DOUBLE_EQ(b.setup_cycles[3], 200.0);
  // gouraud 2·100 + 30·3 + 40·0.5 + 500·4 = 2310; gouraud_z 200 + 50 + 12 + 500 = 762;
  // rejected 30, clears 100 + 192 + 6144, MEM_DATA 42
  const TimingEstimate e = estimate_timing(w, b, 4);
  EXPECT_DOUBLE_EQ(e.pipeline_cycles, 2310 + 762 + 30 + 100 + 192 + 6144 + 42);
  EXPECT_DOUBLE_EQ(e.board_cycles, e.pipeline_cycles);
  // the default profile has none of these terms: the same counters cost it nothing
  EXPECT_DOUBLE_EQ(estimate_timing(w, BoardTiming{}, 4).pipeline_cycles, 0.0);
  BoardTiming bad;
  EXPECT_FALSE(apply_timing_setting(bad, "pixel_cycles_phong=1").ok());
  EXPECT_FALSE(apply_timing_setting(bad, "setup_cycles_flat=-1").ok());
  EXPECT_FALSE(apply_timing_setting(bad, "row_cycles_z=inf").ok());
}

}  // namespace
}  // namespace gpubridge::sim::test
