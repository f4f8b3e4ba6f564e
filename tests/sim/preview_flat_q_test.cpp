// The preview's textured plain kernel when Q is constant along x (docs/simulator.md "Issue 24: the
// textured rows after sim-tex5"): every row then works out its reciprocal once (tex_anchor's flat
// case) instead of once per chunk of eight lanes. The triangles here have a horizontal edge whose
// two vertices share one Q and an apex with another, so Q's step along x is exactly zero but Q
// changes from row to row: a reciprocal hoisted from the wrong row, or from the triangle instead of
// the row, samples other texels. The float routine (keep alpha: preview_simd.cpp, one reciprocal
// per lane, untouched) is the reference, as in preview_test.cpp.
#include <gtest/gtest.h>

#include <random>

#include "random_draws.hpp"

namespace gpubridge::sim::test {
namespace {

// Draws 24 triangles with a horizontal edge (Q = q0 on it, q1 at the apex, q1 != q0) in state c.
Rendered render_flat_q(const Case& c, const DeviceOptions& o) {
  Canvas cv(kW, kH, 0, o);
  Device& d = *cv.dev;
  std::mt19937 rng(c.seed);
  start_frame(d, c, rng, false);
  std::uniform_int_distribution<int> px(-8 * 16, (kW + 8) * 16), py(0, kH * 16);
  std::uniform_int_distribution<std::int32_t> st(-(1 << 26), 1 << 26);
  const int sizes[] = {6, 20, 70, 200};  // narrow boxes, short spans, long spans, larger than the target
  for (int i = 0; i < 24; ++i) {
    const int size = sizes[i % 4] * 16;
    std::uniform_int_distribution<int> dv(size / 4, size);
    const int x = px(rng), y = py(rng);
    const int x1 = x + dv(rng), xa = x + dv(rng) - size / 2, ya = y + (rng() & 1 ? dv(rng) : -dv(rng));
    // Q from 2^20 up (as random_draws.hpp), the apex's at least 2^18 away from the edge's.
    const std::uint32_t q0 = static_cast<std::uint32_t>(rng()) | 0x100000u;
    const std::uint32_t q1 = q0 ^ (0x40000u | (static_cast<std::uint32_t>(rng()) & 0x0FFC0000u));
    w(d, Reg::PRIM, 0);
    const int vx[3] = {x, x1, xa}, vy[3] = {y, y, ya};
    const std::uint32_t q[3] = {q0, q0, q1};
    for (int k = 0; k < 3; ++k) {
      w(d, Reg::COLOR, color(static_cast<std::uint32_t>(rng()), q[k]));
      w(d, Reg::TEXCOORD, (std::uint64_t{static_cast<std::uint32_t>(st(rng))} << 32) | static_cast<std::uint32_t>(st(rng)));
      w(d, Reg::VERTEX, vtx(vx[k], vy[k], 0));
    }
  }
  return end_frame(d);
}

TEST(SimPreviewFlatQ, RowReciprocalSamplesAsTheFloatRoutine) {
  std::mt19937 rng(20261127);
  unsigned textured_pixels = 0, wraps_seen = 0, filters_seen = 0;
  for (int i = 0; i < 60; ++i) {
    Case c = random_case(rng);
    const bool decal = i % 2 == 0;
    c.tri_mode = 2u | (decal ? 1u << 14 : 0u) | (i % 3 == 0 ? 1u << 7 : 0u);  // textured, blend OFF or ALPHA
    c.tex_fmt &= ~(std::uint64_t{3} << 16);  // RGBA8888 texture
    c.fb_fmt = fb_format(kW, kH, 0);
    c.fb_draw = 0;
    c.tex_base = kTexBase;
    wraps_seen |= 1u << ((c.tex_fmt >> 8) & 3);
    filters_seen |= 1u << ((c.tex_fmt >> 12) & 1);
    Case masked = c;
    masked.tri_mode |= 1u << 13;  // keep alpha: the float routine
    const Rendered plain = render_flat_q(c, preview_options(1 + i % 2));
    const Rendered lanes = render_flat_q(masked, preview_options(1));
    ASSERT_EQ(plain.stats.pixels_covered, lanes.stats.pixels_covered) << i;
    ASSERT_TRUE(same_rgb(c, plain, lanes)) << "case " << i;
    textured_pixels += static_cast<unsigned>(plain.stats.pixels_textured);
  }
  EXPECT_GT(textured_pixels, 20000u);
  EXPECT_EQ(wraps_seen, 7u);    // REPEAT, CLAMP, MIRROR
  EXPECT_EQ(filters_seen, 3u);  // nearest and bilinear
}

}  // namespace
}  // namespace gpubridge::sim::test
