// The vector routines (narrow_simd, span_simd, the textured span) give the bytes of the scalar
// routines: random render states over every TRI_MODE / TEX_FMT / FB_FORMAT field, random triangles
// of every size class, rendered with DeviceOptions::vector_routines on and off; colour, depth and
// the pixel counters must be identical. Some states alias the buffers (texture inside the colour
// buffer, depth overlapping colour) so the vector routines' disjointness conditions are exercised.
#include <gtest/gtest.h>

#include <random>

#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

constexpr unsigned kW = 96, kH = 80;
constexpr std::uint32_t kTexBase = 0x200000;

struct Case {
  std::uint64_t tri_mode = 0, tex_fmt = 0, fb_fmt = 0;
  std::uint32_t fb_draw = 0, fb_z = Canvas::kZBase, tex_base = kTexBase;
  std::uint32_t seed = 0;
};

Case random_case(std::mt19937& rng) {
  auto bit = [&](unsigned percent) { return std::uniform_int_distribution<unsigned>(0, 99)(rng) < percent; };
  auto pick = [&](unsigned n) { return std::uniform_int_distribution<unsigned>(0, n - 1)(rng); };
  Case c;
  c.seed = static_cast<std::uint32_t>(rng());
  const bool z_test = bit(60), z_write = bit(60);
  c.tri_mode = std::uint64_t{bit(70)}               // Gouraud
               | (std::uint64_t{bit(60)} << 1)      // textured
               | (std::uint64_t{z_test} << 2)       //
               | (std::uint64_t{pick(8)} << 3)      // Z_FUNC
               | (std::uint64_t{z_write} << 6)      //
               | (std::uint64_t{bit(50) ? pick(4) : 0} << 7)  // blend
               | (std::uint64_t{bit(30)} << 9)      // dither
               | (std::uint64_t{bit(25) ? pick(16) : 0} << 10)  // write mask
               | (std::uint64_t{bit(30)} << 14)     // decal
               | (std::uint64_t{bit(50)} << 15)     // temporal dither (with dither)
               | (std::uint64_t{pick(16)} << 16);   // dither phase
  const unsigned wl = 3 + pick(5), hl = 3 + pick(5);
  c.tex_fmt = wl | (hl << 4) | (std::uint64_t{pick(3)} << 8) | (std::uint64_t{pick(3)} << 10) |
              (std::uint64_t{bit(60)} << 12) | (std::uint64_t{bit(70) ? 0 : 1 + pick(2)} << 16);
  c.fb_fmt = fb_format(kW, kH, bit(75) ? 0 : 1 + pick(2));
  if (bit(10)) c.tex_base = 0x100 * pick(16);          // the texture is (part of) the colour buffer
  if (bit(10)) {  // depth words 4 or 8 pixels behind the colour words: inside one 8-pixel chunk
    c.fb_draw = 64;
    c.fb_z = 64 - 16 * (1 + pick(2));
    // An ordering test needs a depth test whose outcome depends on what it reads.
    c.tri_mode = (c.tri_mode & ~std::uint64_t{0x3C}) | 4 | (std::uint64_t{bit(50) ? 1u : 4u} << 3);
  }
  return c;
}

struct Rendered {
  std::vector<std::uint8_t> memory;  // colour, depth and texture regions
  DeviceStats stats;
};

Rendered render(const Case& c, bool vector) {
  DeviceOptions o;
  o.vector_routines = vector;
  Canvas cv(kW, kH, 0, o);
  Device& d = *cv.dev;
  std::mt19937 rng(c.seed);
  auto mem = d.memory();
  for (std::uint32_t i = 0; i < 128 * 128 * 4; ++i) mem[kTexBase + i] = static_cast<std::uint8_t>(rng());
  w(d, Reg::FB_FORMAT, c.fb_fmt);
  w(d, Reg::FB_DRAW, c.fb_draw);
  w(d, Reg::FB_Z, c.fb_z);
  w(d, Reg::CLEAR_COLOR, rng());
  w(d, Reg::CLEAR, 0);
  w(d, Reg::CLEAR_DEPTH, rng() & 0xFFFFFF);
  w(d, Reg::CLEAR_Z, 0);
  w(d, Reg::TEX_BASE, c.tex_base);
  w(d, Reg::TEX_FMT, c.tex_fmt);
  w(d, Reg::TRI_MODE, c.tri_mode);
  std::uniform_int_distribution<int> px(-16 * 16, (kW + 16) * 16), py(-16 * 16, (kH + 16) * 16);
  std::uniform_int_distribution<std::int32_t> st(-(1 << 26), 1 << 26);
  const int sizes[] = {6, 20, 70, 200};  // px: narrow boxes, short spans, long spans, larger than the target
  for (int i = 0; i < 24; ++i) {
    const int size = sizes[i % 4] * 16;
    std::uniform_int_distribution<int> dv(-size, size);
    const int x = px(rng), y = py(rng);
    const bool affine = rng() & 1;
    const std::uint32_t q0 = static_cast<std::uint32_t>(rng()) | 0x100000u;
    w(d, Reg::PRIM, 0);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t q = affine ? q0 : static_cast<std::uint32_t>(rng()) | 0x100000u;
      w(d, Reg::COLOR, color(static_cast<std::uint32_t>(rng()), q));
      w(d, Reg::TEXCOORD, (std::uint64_t{static_cast<std::uint32_t>(st(rng))} << 32) | static_cast<std::uint32_t>(st(rng)));
      w(d, Reg::VERTEX, vtx(k == 0 ? x : x + dv(rng), k == 0 ? y : y + dv(rng), rng() & 0xFFFFFF));
    }
  }
  d.drain();
  const auto m = d.memory();
  Rendered r;
  r.memory.assign(m.begin(), m.begin() + kTexBase + 128 * 128 * 4);
  r.stats = d.stats();
  return r;
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
}

TEST(SimVectorRoutines, SameBytesAndCountersAsScalar) {
  std::mt19937 rng(20261121);
  unsigned textured = 0, aliased = 0;
  for (int i = 0; i < 300; ++i) {
    const Case c = random_case(rng);
    const Rendered v = render(c, true), s = render(c, false);
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
    const Rendered v = render(c, true), s = render(c, false);
    expect_same(c, v, s, i);
    if (::testing::Test::HasFatalFailure()) return;
    phases |= (s.stats.pixels_depth_passed > 0) << phase;
  }
  EXPECT_EQ(phases, 0xFFFFu);  // every phase drew pixels
}

}  // namespace
}  // namespace gpubridge::sim::test
