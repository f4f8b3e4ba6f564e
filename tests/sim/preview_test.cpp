// The preview rasteriser (`--accuracy preview`, backends/sim/src/preview_simd.cpp): the same bytes
// for any thread count and run; the exact path's coverage (top-left rule included, up to the
// largest coordinates the protocol carries); colour within 1 LSB and Z within a few LSB of the
// exact values. The suite runs under ASan/UBSan in the sanitizer build, so the extreme cases also
// check that no float lane reaches an integer conversion out of range.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "random_draws.hpp"

namespace gpubridge::sim::test {
namespace {

TEST(SimPreview, SameBytesForAnyThreadCountAndRun) {
  std::mt19937 rng(20261126);
  unsigned differs_from_exact = 0;
  for (int i = 0; i < 120; ++i) {
    const Case c = random_case(rng);
    const Rendered one = render(c, preview_options(1));
    const Rendered two = render(c, preview_options(2));
    const Rendered three = render(c, preview_options(3));
    const Rendered again = render(c, preview_options(1));
    ASSERT_EQ(one.memory, two.memory) << "case " << i << " TRI_MODE 0x" << std::hex << c.tri_mode;
    ASSERT_EQ(one.memory, three.memory) << "case " << i;
    ASSERT_EQ(one.memory, again.memory) << "case " << i;
    EXPECT_EQ(one.stats.pixels_depth_passed, two.stats.pixels_depth_passed) << i;
    const Rendered exact = render(c, DeviceOptions{});
    // Coverage is the exact path's in every state (before the depth test: Z differs slightly).
    EXPECT_EQ(one.stats.pixels_covered, exact.stats.pixels_covered) << "case " << i;
    differs_from_exact += one.memory != exact.memory;
  }
  // The cases ran the preview routine (Gouraud, Z and texels differ from the exact ones).
  EXPECT_GT(differs_from_exact, 30u);
}

// Flat colour, no texture, no depth: nothing is interpolated, so every byte is the exact path's;
// any difference would be coverage (the edge functions, the top-left rule, the span solve).
TEST(SimPreview, FlatDrawsAreTheExactBytes) {
  std::mt19937 rng(7);
  for (int i = 0; i < 200; ++i) {
    Case c = random_case(rng);
    c.tri_mode &= ~(std::uint64_t{1} | 2u | 4u | (1u << 6));  // no Gouraud, texture, Z test or Z write
    const Rendered p = render(c, preview_options(1 + i % 2)), e = render(c, DeviceOptions{});
    ASSERT_EQ(p.memory, e.memory) << "case " << i << " TRI_MODE 0x" << std::hex << c.tri_mode << " FB_FORMAT 0x"
                                  << c.fb_fmt;
    EXPECT_EQ(p.stats.pixels_covered, e.stats.pixels_covered) << i;
  }
}

// Gouraud colour and Z against the exact values, pixel by pixel (depth ALWAYS + write, so every
// covered pixel is written by the last triangle covering it in both renders). RGBA8888 draws take
// the plain kernel (preview_plain.hpp), RGB565 ones the float routine (preview_simd.cpp).
struct PreviewErrors {
  int max_c = 0, max_z = 0;
};
PreviewErrors gouraud_errors(unsigned fb_fmt_code) {
  std::mt19937 rng(11);
  PreviewErrors err;
  const std::size_t bpp = fb_fmt_code == 0 ? 4 : 2;
  for (int i = 0; i < 60; ++i) {
    Case c = random_case(rng);
    c.tri_mode = 1u | 4u | (std::uint64_t{7} << 3) | (1u << 6);  // Gouraud, Z test ALWAYS, Z write
    c.fb_fmt = fb_format(kW, kH, fb_fmt_code);
    c.fb_draw = 0;
    c.fb_z = Canvas::kZBase;
    const Rendered p = render(c, preview_options(1)), e = render(c, DeviceOptions{});
    for (std::size_t px = 0; px < std::size_t{kW} * kH; ++px) {
      if (bpp == 4)  // RGB565 quantises the colour: only Z is compared there
        for (std::size_t ch = 0; ch < 4; ++ch)
          err.max_c = std::max(err.max_c, std::abs(int(p.memory[px * 4 + ch]) - int(e.memory[px * 4 + ch])));
      auto z = [&](const Rendered& r) {
        const std::uint8_t* q = &r.memory[Canvas::kZBase + px * 4];
        return (int(q[1]) << 16) | (int(q[2]) << 8) | q[3];
      };
      err.max_z = std::max(err.max_z, std::abs(z(p) - z(e)));
    }
  }
  return err;
}

TEST(SimPreview, PlainDrawsColourAndZWithinOneLsbOfExact) {
  const PreviewErrors err = gouraud_errors(0);
  // Fixed-point planes within 2^-12 of the double ones (colour 8.24, Z 32.32): only values that
  // close to a rounding boundary round the other way, by one.
  EXPECT_LE(err.max_c, 1);
  EXPECT_LE(err.max_z, 1);
  // Nothing asserts that some pixel differs: whether one of these values lies that close to a half
  // depends on the compiler's double arithmetic in setup (gcc 12: one Z value of the 60 cases;
  // clang 14: none). SameBytesForAnyThreadCountAndRun checks that preview differs from exact.
}

TEST(SimPreview, FloatDrawsZWithinEightLsbOfExact) {
  const PreviewErrors err = gouraud_errors(1);
  // Z is below 2^24, where float has no fraction bit: the base value, the two products and the two
  // sums each round by up to half a unit of up to 2^25.
  EXPECT_LE(err.max_z, 8);
  EXPECT_GT(err.max_z, 0);
}

// An RGBA8888 texture into an RGBA8888 framebuffer at the canvas's bases; records the wrap mode
// and filter seen, and returns the same case with "keep alpha" set, which sends it through the
// float routine instead of the textured plain kernel.
Case textured_rgba8888(Case& c, unsigned& wraps_seen, unsigned& filters_seen) {
  c.tex_fmt &= ~(std::uint64_t{3} << 16);  // RGBA8888 texture
  c.fb_fmt = fb_format(kW, kH, 0);
  c.fb_draw = 0;
  c.fb_z = Canvas::kZBase;
  c.tex_base = kTexBase;
  wraps_seen |= 1u << ((c.tex_fmt >> 8) & 3);
  filters_seen |= 1u << ((c.tex_fmt >> 12) & 1);
  Case masked = c;
  masked.tri_mode |= 1u << 13;  // keep alpha: the float routine
  return masked;
}

// Textured RGBA8888 draws take the plain kernel's texture stage (preview_plain_kernel.inc: lanes,
// gathers); with the alpha channel write-masked the same draws take the float routine and the
// shared texture stage (preview_simd.cpp, texture8.hpp). Both compute the texel coordinates with
// the same float operations, so with a decal texture or a flat colour, and no depth, the RGB
// bytes must be the same in every wrap mode, texture size and filter; any difference is the new
// stage's addressing, fetch, filter or combine.
TEST(SimPreview, TexturedPlainKernelSamplesAsTheFloatRoutine) {
  std::mt19937 rng(424242);
  unsigned textured_pixels = 0, wraps_seen = 0, filters_seen = 0;
  for (int i = 0; i < 80; ++i) {
    Case c = random_case(rng);
    const bool decal = i % 2 == 0;
    const bool alpha_blend = i % 3 == 0;
    // Textured, decal or flat modulate, no depth, blend OFF or ALPHA, no write mask, no dither.
    c.tri_mode = 2u | (decal ? 1u << 14 : 0u) | (alpha_blend ? 1u << 7 : 0u);
    const Case masked = textured_rgba8888(c, wraps_seen, filters_seen);
    const Rendered plain = render(c, preview_options(1)), lanes = render(masked, preview_options(1 + i % 2));
    EXPECT_EQ(plain.stats.pixels_covered, lanes.stats.pixels_covered) << i;
    ASSERT_TRUE(same_rgb(c, plain, lanes)) << "case " << i;
    textured_pixels += static_cast<unsigned>(plain.stats.pixels_textured);
  }
  EXPECT_GT(textured_pixels, 10000u);
  EXPECT_EQ(wraps_seen, 7u);    // REPEAT, CLAMP, MIRROR
  EXPECT_EQ(filters_seen, 3u);  // nearest and bilinear
}

// The same comparison with the depth test on (LESS, LEQUAL, GREATER, GEQUAL, ALWAYS; Z written or
// not), so chunks pass whole, in part or not at all and the wide kernel's deferred combine and
// store (docs/simulator.md "Preview": a chunk is finished after the next one's fetch) meets every
// case, across rows and triangles. Each triangle has one Z at its three vertices: both routines
// then have that Z exactly at every pixel (fixed point and float alike), so the same pixels pass
// and the colour and depth bytes must be the same.
TEST(SimPreview, TexturedPlainKernelWithDepthSamplesAsTheFloatRoutine) {
  std::mt19937 rng(20261127);
  const unsigned funcs[] = {1, 3, 4, 6, 7};  // LESS, LEQUAL, GREATER, GEQUAL, ALWAYS
  unsigned textured_pixels = 0, failed_pixels = 0, wraps_seen = 0, filters_seen = 0;
  for (int i = 0; i < 80; ++i) {
    Case c = random_case(rng);
    const bool decal = i % 2 == 0, alpha_blend = i % 3 == 0, z_write = i % 4 != 3;
    c.tri_mode = 2u | 4u | (std::uint64_t{funcs[i % 5]} << 3) | (z_write ? 1u << 6 : 0u) | (decal ? 1u << 14 : 0u) |
                 (alpha_blend ? 1u << 7 : 0u);
    const Case masked = textured_rgba8888(c, wraps_seen, filters_seen);
    const Rendered plain = render(c, preview_options(1 + i % 2), true), lanes = render(masked, preview_options(1), true);
    ASSERT_EQ(plain.stats.pixels_covered, lanes.stats.pixels_covered) << i;
    ASSERT_EQ(plain.stats.pixels_depth_passed, lanes.stats.pixels_depth_passed) << i;
    ASSERT_TRUE(same_rgb(c, plain, lanes)) << "case " << i;
    for (std::size_t px = 0; px < std::size_t{kW} * kH; ++px) {
      for (std::size_t b = 0; b < 4; ++b)
        ASSERT_EQ(plain.memory[Canvas::kZBase + px * 4 + b], lanes.memory[Canvas::kZBase + px * 4 + b])
            << "case " << i << " depth of pixel " << px;
    }
    textured_pixels += static_cast<unsigned>(plain.stats.pixels_textured);
    failed_pixels += static_cast<unsigned>(plain.stats.pixels_covered - plain.stats.pixels_depth_passed);
  }
  EXPECT_GT(textured_pixels, 10000u);
  EXPECT_GT(failed_pixels, 10000u);  // the depth test rejected pixels: chunks passed in part
  EXPECT_EQ(wraps_seen, 7u);
  EXPECT_EQ(filters_seen, 3u);
}

// Vertices anywhere in the s12.4 range (edge values up to 2^36), S/T anywhere in s8.24, Q anywhere
// including 0: no undefined behaviour (UBSan), coverage still the exact test, and the same bytes
// with one and two threads.
TEST(SimPreview, ExtremeCoordinatesAndTexelsStayDefined) {
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> any(-32768, 32767);
  for (int round = 0; round < 8; ++round) {
    const bool textured = round % 2 == 1;
    auto draw = [&](const DeviceOptions& o, std::uint32_t seed) {
      std::mt19937 r(seed);
      Canvas cv(kW, kH, 0, o);
      Device& d = *cv.dev;
      w(d, Reg::TEX_BASE, kTexBase);
      w(d, Reg::TEX_FMT, 7u | (7u << 4) | (1u << 12));  // 128x128 RGBA8888, bilinear, REPEAT
      w(d, Reg::TRI_MODE, textured ? 2u | (1u << 14) : 0u);  // decal texture, or flat
      w(d, Reg::PRIM, 0);
      for (int t = 0; t < 60; ++t) {
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t q = r() % 4 == 0 ? 0u : static_cast<std::uint32_t>(r());
          w(d, Reg::COLOR, color(static_cast<std::uint32_t>(r()), q));
          w(d, Reg::TEXCOORD, (std::uint64_t{static_cast<std::uint32_t>(r())} << 32) | static_cast<std::uint32_t>(r()));
          // Half the vertices near the target, half anywhere: long edges crossing it at any angle.
          const int x = r() % 2 ? any(r) : static_cast<int>(r() % (16 * kW)), y = r() % 2 ? any(r) : static_cast<int>(r() % (16 * kH));
          w(d, Reg::VERTEX, vtx(x, y, static_cast<std::uint32_t>(r())));
        }
      }
      d.drain();
      const auto m = d.memory();
      return std::pair{std::vector<std::uint8_t>(m.begin(), m.begin() + kW * kH * 4), d.stats().pixels_covered};
    };
    const std::uint32_t seed = static_cast<std::uint32_t>(rng());
    const auto one = draw(preview_options(1), seed), two = draw(preview_options(2), seed);
    const auto exact = draw(DeviceOptions{}, seed);
    EXPECT_EQ(one.first, two.first) << "round " << round;
    EXPECT_EQ(one.second, exact.second) << "round " << round;  // coverage
    EXPECT_GT(exact.second, 0u) << "round " << round;
    if (!textured) {
      EXPECT_EQ(one.first, exact.first) << "round " << round;  // flat: the exact bytes
    }
  }
}

}  // namespace
}  // namespace gpubridge::sim::test
