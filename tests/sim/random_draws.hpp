#pragma once
// Random render states over every TRI_MODE / TEX_FMT / FB_FORMAT field and random triangles drawn
// in them (vector_equivalence_test.cpp, preview_test.cpp). Some states alias the buffers (texture
// inside the colour buffer, depth overlapping colour).
#include <random>
#include <vector>

#include "sim_test_util.hpp"

namespace gpubridge::sim::test {

inline constexpr unsigned kW = 96, kH = 80;
inline constexpr std::uint32_t kTexBase = 0x200000;

struct Case {
  std::uint64_t tri_mode = 0, tex_fmt = 0, fb_fmt = 0;
  std::uint32_t fb_draw = 0, fb_z = Canvas::kZBase, tex_base = kTexBase;
  std::uint32_t seed = 0;
};

inline Case random_case(std::mt19937& rng) {
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

// Device options with the vector routines on, or off (the reference routines they are compared with).
inline DeviceOptions vector_options(bool vector) {
  DeviceOptions o;
  o.vector_routines = vector;
  return o;
}

// The vector routines' rendering v of case c (number i) against the reference routines' s: the
// bytes, then the counters the draws feed, then every counter.
inline void expect_same(const Case& c, const Rendered& v, const Rendered& s, int i) {
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

// Two preview renderings of case c with the same R, G and B in every pixel of the colour buffer
// (its alpha is not compared: the float routine keeps it, the lanes' masked case too).
inline ::testing::AssertionResult same_rgb(const Case& c, const Rendered& a, const Rendered& b) {
  for (std::size_t px = 0; px < std::size_t{kW} * kH; ++px)
    for (std::size_t ch = 0; ch < 3; ++ch)
      if (a.memory[px * 4 + ch] != b.memory[px * 4 + ch])
        return ::testing::AssertionFailure() << "pixel " << px << " channel " << ch << ": " << int{a.memory[px * 4 + ch]}
                                             << " against " << int{b.memory[px * 4 + ch]} << ", TRI_MODE 0x" << std::hex
                                             << c.tri_mode << " TEX_FMT 0x" << c.tex_fmt;
  return ::testing::AssertionSuccess();
}

// A random texture at kTexBase, case c's buffers and state, the colour buffer cleared to a random
// colour and, with clear_depth, the depth buffer to a random depth (render, preview_flat_q_test.cpp).
inline void start_frame(Device& d, const Case& c, std::mt19937& rng, bool clear_depth) {
  auto mem = d.memory();
  for (std::uint32_t i = 0; i < 128 * 128 * 4; ++i) mem[kTexBase + i] = static_cast<std::uint8_t>(rng());
  w(d, Reg::FB_FORMAT, c.fb_fmt);
  w(d, Reg::FB_DRAW, c.fb_draw);
  w(d, Reg::FB_Z, c.fb_z);
  w(d, Reg::CLEAR_COLOR, rng());
  w(d, Reg::CLEAR, 0);
  if (clear_depth) {
    w(d, Reg::CLEAR_DEPTH, rng() & 0xFFFFFF);
    w(d, Reg::CLEAR_Z, 0);
  }
  w(d, Reg::TEX_BASE, c.tex_base);
  w(d, Reg::TEX_FMT, c.tex_fmt);
  w(d, Reg::TRI_MODE, c.tri_mode);
}

// The frame drawn: the memory up to the texture's end and the counters (render, preview_flat_q_test.cpp).
inline Rendered end_frame(Device& d) {
  d.drain();
  const auto m = d.memory();
  Rendered r;
  r.memory.assign(m.begin(), m.begin() + kTexBase + 128 * 128 * 4);
  r.stats = d.stats();
  return r;
}

// Draws 24 random triangles of four size classes (narrow boxes, short and long spans, larger than
// the target) in state c with device options o; the memory covers colour, depth and texture.
// flat_z: each triangle's three vertices take its first vertex's Z, below 2^23 (so that Z + 0.5,
// the planes' rounding bias, is exact in float as well as in fixed point); the same random draws.
inline Rendered render(const Case& c, const DeviceOptions& o, bool flat_z = false) {
  Canvas cv(kW, kH, 0, o);
  Device& d = *cv.dev;
  std::mt19937 rng(c.seed);
  start_frame(d, c, rng, true);
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
    std::uint32_t z0 = 0;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t q = affine ? q0 : static_cast<std::uint32_t>(rng()) | 0x100000u;
      w(d, Reg::COLOR, color(static_cast<std::uint32_t>(rng()), q));
      w(d, Reg::TEXCOORD, (std::uint64_t{static_cast<std::uint32_t>(st(rng))} << 32) | static_cast<std::uint32_t>(st(rng)));
      const int vx = k == 0 ? x : x + dv(rng), vy = k == 0 ? y : y + dv(rng);
      const std::uint32_t z = static_cast<std::uint32_t>(rng()) & 0xFFFFFF;
      if (k == 0) z0 = z & 0x7FFFFF;
      w(d, Reg::VERTEX, vtx(vx, vy, flat_z ? z0 : z));
    }
  }
  return end_frame(d);
}

}  // namespace gpubridge::sim::test
