// The vector routines (narrow_simd, span_simd, the textured span) give the bytes of the scalar
// routines: random render states over every TRI_MODE / TEX_FMT / FB_FORMAT field, random triangles
// of every size class, rendered with DeviceOptions::vector_routines on and off; colour, depth and
// the pixel counters must be identical. Some states alias the buffers (texture inside the colour
// buffer, depth overlapping colour) so the vector routines' disjointness conditions are exercised.
#include <gtest/gtest.h>

#include <random>

#include "random_draws.hpp"

namespace gpubridge::sim::test {
namespace {

TEST(SimVectorRoutines, SameBytesAndCountersAsScalar) {
  std::mt19937 rng(20261121);
  unsigned textured = 0, aliased = 0;
  for (int i = 0; i < 300; ++i) {
    const Case c = random_case(rng);
    const Rendered v = render(c, vector_options(true)), s = render(c, vector_options(false));
    expect_same(c, v, s, i);
    if (::testing::Test::HasFatalFailure()) return;
    textured += (c.tri_mode & 2) && s.stats.pixels_textured > 0;
    aliased += c.tex_base < kW * kH * 4 || c.fb_z < kW * kH * 4;
  }
  // The random states reached the features under test.
  EXPECT_GT(textured, 100u);
  EXPECT_GT(aliased, 20u);
}

// The temporal dither (TRI_MODE.TEMPORAL, every DITHER_PHASE) in both packed formats, with the
// rest of the state random: both vector routines quantise as the scalar one.
TEST(SimVectorRoutines, TemporalDitherSameBytesAsScalar) {
  std::mt19937 rng(20260523);
  unsigned phases = 0;
  for (int i = 0; i < 96; ++i) {
    Case c = random_case(rng);
    const unsigned phase = static_cast<unsigned>(i) % 16;
    c.tri_mode = (c.tri_mode & ~(std::uint64_t{31} << 15)) | (1u << 9) | (1u << 15) | (std::uint64_t{phase} << 16);
    c.fb_fmt = fb_format(kW, kH, 1 + (i / 16) % 2);  // RGB565, RGBA2222
    const Rendered v = render(c, vector_options(true)), s = render(c, vector_options(false));
    expect_same(c, v, s, i);
    if (::testing::Test::HasFatalFailure()) return;
    phases |= (s.stats.pixels_depth_passed > 0) << phase;
  }
  EXPECT_EQ(phases, 0xFFFFu);  // every phase drew pixels
}

}  // namespace
}  // namespace gpubridge::sim::test
