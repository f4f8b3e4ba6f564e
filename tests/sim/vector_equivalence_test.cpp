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

DeviceOptions vector_options(bool vector) {
  DeviceOptions o;
  o.vector_routines = vector;
  return o;
}

void expect_same(const Case& c, const Rendered& v, const Rendered& s, int i) {
  ASSERT_EQ(v.memory, s.memory) << "case " << i << ": TRI_MODE 0x" << std::hex << c.tri_mode << " TEX_FMT 0x"
                                << c.tex_fmt << " FB_FORMAT 0x" << c.fb_fmt << " FB_DRAW 0x" << c.fb_draw << " FB_Z 0x"
                                << c.fb_z << " TEX_BASE 0x" << c.tex_base;
  EXPECT_EQ(v.stats.pixels_covered, s.stats.pixels_covered) << i;
  EXPECT_EQ(v.stats.pixels_depth_passed, s.stats.pixels_depth_passed) << i;
  EXPECT_EQ(v.stats.pixels_textured, s.stats.pixels_textured) << i;
  EXPECT_EQ(v.stats.pixels_blended, s.stats.pixels_blended) << i;
  EXPECT_EQ(v.stats.texel_bytes, s.stats.texel_bytes) << i;
  EXPECT_TRUE(v.stats == s.stats) << i << ": the timing counters too";
}

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
