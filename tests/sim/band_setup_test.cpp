// Batches of small triangles drawn by the band workers (backends/sim/src/renderer.hpp): with N
// threads the front end sets the batch up and each worker draws its own rows of every triangle (a
// run of whole 16-row bands each, cut where the batch's work splits evenly; whoever sets up, the
// tests hold for any split of the work). The bytes, the error flags
// and every counter (triangles rasterised and rejected, rows and columns per state class, pixels)
// must be those of one thread, each triangle counted once: small triangles around the band edges,
// triangles that draw nothing (D = 0, between sample rows, above the framebuffer, outside the
// scissor), several states and batches longer than one, in the exact and the preview path, with
// full and truncated subpixel bits.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "draw_state.hpp"
#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

constexpr unsigned kW = 80, kH = 72;

struct Result {
  std::vector<std::uint8_t> bytes;
  DeviceStats stats;
  std::uint16_t errors = 0;
  std::uint64_t kicked = 0;
};

// Random small triangles whose vertices lie within a few pixels of a band edge (rows 16, 32, ...,
// including row 0 and the bottom of the framebuffer), a fifth of them made to draw nothing.
Result render(DeviceOptions o, std::uint32_t seed) {
  std::mt19937 r(seed);
  Canvas cv(kW, kH, 0, o);
  Device& d = *cv.dev;
  Result out;
  // Gouraud with LESS and the Z write, flat with ALWAYS, Gouraud ALPHA-blended, then a scissored
  // state: each state change hands the workers a batch; the first state's 5,000 triangles also fill
  // more than one 4,096-triangle batch.
  const std::uint64_t modes[] = {1u | 4u | (1u << 3) | (1u << 6), 4u | (7u << 3) | (1u << 6), 1u | (1u << 7),
                                 1u | 4u | (3u << 3) | (1u << 6)};
  const int counts[] = {5000, 800, 800, 800};
  for (int s = 0; s < 4; ++s) {
    w(d, Reg::SCISSOR, s == 3 ? scissor(5, 13, kW - 7, kH - 14) : scissor(0, 0, 2047, 2047));
    w(d, Reg::TRI_MODE, modes[s]);
    w(d, Reg::PRIM, 0);
    for (int t = 0; t < counts[s]; ++t) {
      const int band = 16 * static_cast<int>(r() % 6);  // 0, 16, ..., 80 (past the bottom)
      const int cx = static_cast<int>(r() % (16 * kW)), cy = 16 * band + static_cast<int>(r() % 129) - 64;
      const unsigned kind = r() % 10;
      int x[3], y[3];
      for (int k = 0; k < 3; ++k) {
        x[k] = cx + static_cast<int>(r() % 161) - 80;
        y[k] = cy + static_cast<int>(r() % 161) - 80;
      }
      if (kind == 0) {  // collinear: D = 0
        x[2] = 2 * x[1] - x[0];
        y[2] = 2 * y[1] - y[0];
      } else if (kind == 1) {  // a sliver between two rows' sample points (y + 8 mod 16 in 1..15)
        const int row = 16 * (band + static_cast<int>(r() % 3) - 1);
        for (int k = 0; k < 3; ++k) y[k] = row + 9 + static_cast<int>(r() % 14);
      }
      for (int k = 0; k < 3; ++k) {
        w(d, Reg::COLOR, color(static_cast<std::uint32_t>(r())));
        w(d, Reg::VERTEX, vtx(x[k], y[k], static_cast<std::uint32_t>(r())));
      }
      ++out.kicked;
    }
  }
  d.drain();
  const auto m = d.memory();
  out.bytes.assign(m.begin(), m.begin() + Canvas::kZBase + kW * kH * 4);
  out.stats = d.stats();
  out.errors = d.errors();
  return out;
}

void expect_same_for_any_thread_count(DeviceOptions o, const char* what) {
  o.threads = 1;
  const Result one = render(o, 24);
  // The stream exercises what it is meant to: drawn and rejected triangles, every one counted.
  EXPECT_GT(one.stats.triangles_rasterised, one.kicked / 2) << what;
  EXPECT_GT(one.stats.triangles_rejected, one.kicked / 10) << what;
  EXPECT_EQ(one.stats.triangles_rasterised + one.stats.triangles_rejected, one.kicked) << what;
  EXPECT_GT(one.stats.pixels_covered, 10000u) << what;
  for (unsigned threads : {2u, 3u, 4u}) {
    o.threads = threads;
    const Result n = render(o, 24);
    EXPECT_EQ(n.bytes, one.bytes) << what << ", threads " << threads;
    EXPECT_TRUE(n.stats == one.stats) << what << ", threads " << threads << ": rasterised "
                                      << n.stats.triangles_rasterised << " vs " << one.stats.triangles_rasterised
                                      << ", rejected " << n.stats.triangles_rejected << " vs "
                                      << one.stats.triangles_rejected << ", covered " << n.stats.pixels_covered
                                      << " vs " << one.stats.pixels_covered;
    EXPECT_EQ(n.errors, one.errors) << what << ", threads " << threads;
  }
}

TEST(SimBandSetup, ExactSameBytesAndCountersForAnyThreadCount) {
  expect_same_for_any_thread_count(DeviceOptions{}, "exact");
}

TEST(SimBandSetup, PreviewSameBytesAndCountersForAnyThreadCount) {
  expect_same_for_any_thread_count(preview_options(1), "preview");
}

// Truncated vertex coordinates (subpixel_bits < 4) move the rows and the box.
TEST(SimBandSetup, TruncatedSubpixelsSameBytesAndCounters) {
  DeviceOptions exact;
  exact.accuracy.subpixel_bits = 1;
  expect_same_for_any_thread_count(exact, "exact, subpixel_bits=1");
  DeviceOptions preview = preview_options(1);
  preview.accuracy.subpixel_bits = 2;
  expect_same_for_any_thread_count(preview, "preview, subpixel_bits=2");
}

// Whether a state's bands may be drawn by different workers (DrawState::bands_independent, decided
// once per state): not when the colour and depth buffers share a byte (with depth on), nor when
// the texture shares a byte with a buffer the draw writes.
TEST(SimBandSetup, BandsIndependentOnlyWithoutAliasing) {
  constexpr unsigned w = 64, h = 48;
  constexpr std::uint32_t buffer = w * h * 4;  // bytes of either buffer (RGBA8888)
  constexpr std::uint64_t vram = 1u << 20;
  constexpr std::uint64_t depth_less = 4u | (1u << 3) | (1u << 6), textured = 2u;
  const std::uint64_t tex_16x16 = 4u | (4u << 4);  // 1 KiB of RGBA8888
  auto state = [&](std::uint64_t mode, std::uint32_t z_at, std::uint32_t tex_at) {
    return decode_draw_state(RegisterValues{mode, tex_at, tex_16x16, scissor(0, 0, 2047, 2047), 0, z_at, fb_format(w, h)},
                             vram);
  };
  EXPECT_TRUE(state(depth_less, buffer, 0x80000).bands_independent);        // depth right after colour
  EXPECT_FALSE(state(depth_less, buffer - 16, 0x80000).bands_independent);  // their last and first 16 bytes shared
  EXPECT_TRUE(state(1u, buffer - 16, 0x80000).bands_independent);           // no depth: the Z address is unused
  EXPECT_TRUE(state(depth_less | textured, buffer, 2 * buffer).bands_independent);
  EXPECT_FALSE(state(depth_less | textured, buffer, buffer - 1024 + 16).bands_independent);  // texture over colour's end
  EXPECT_FALSE(state(depth_less | textured, buffer, 2 * buffer - 16).bands_independent);     // texture over depth's end
  EXPECT_TRUE(state(textured, buffer, 2 * buffer - 16).bands_independent);                  // no depth
  EXPECT_FALSE(state(textured, buffer, 0).bands_independent);                               // texture over colour
}

}  // namespace
}  // namespace gpubridge::sim::test
