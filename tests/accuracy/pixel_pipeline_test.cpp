// Hard cases 23-24: blend corner values and ordered dither. Expected values are computed here from
// the formulas of docs/protocol.md section 11 with plain integer arithmetic (round half up of
// x / 255 as floor((2x + 255) / 510)), independently of the simulator's div255.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "sim_harness.hpp"

namespace gpubridge::accuracy {
namespace {

using geometry::DeviceTriangle;
using protocol::BlendMode;

int round_div255(int x) { return (2 * x + 255) / 510; }

int blend_expected(BlendMode m, int src, int dst, int alpha) {
  switch (m) {
    case BlendMode::Alpha: return round_div255(src * alpha + dst * (255 - alpha));
    case BlendMode::Add: return std::min(255, src + dst);
    case BlendMode::Multiply: return round_div255(src * dst);
    default: return src;
  }
}

std::vector<DeviceTriangle> full_target(std::uint32_t rgba) {
  const auto a = dv(0, 0, 0, rgba), b = dv(64 * 16, 0, 0, rgba), c = dv(64 * 16, 64 * 16, 0, rgba),
             d = dv(0, 64 * 16, 0, rgba);
  return {{a, b, c}, {a, c, d}};
}

// Bound: exact equality with the integer formula for every mode, alpha in {0, 1, 0x7F, 0x80, 0xFE,
// 0xFF}, source and destination channels in {0, 1, 127, 128, 254, 255}.
TEST(PixelPipeline, BlendCornerValues_ExactFormula) {
  SimHarness h;
  const int values[] = {0, 1, 127, 128, 254, 255};
  const int alphas[] = {0, 1, 0x7F, 0x80, 0xFE, 0xFF};
  for (auto mode : {BlendMode::Off, BlendMode::Alpha, BlendMode::Add, BlendMode::Multiply}) {
    int cell = 0;
    struct Case { int x, y, src, dst, alpha; };
    std::vector<Case> cases;
    for (int alpha : alphas)
      for (int src : values)
        for (int dst : values) {
          const int x = cell % 64, y = cell / 64;
          ++cell;
          // One pixel: scissor to it, clear it to dst, draw src over it.
          h.scissor(unsigned(x), unsigned(y), unsigned(x + 1), unsigned(y + 1));
          const std::uint32_t dst_word = std::uint32_t(dst) * 0x01010101u;
          h.clear(dst_word);
          geometry::RenderState st;
          st.gouraud = false;
          st.blend = mode;
          h.state(st);
          const std::uint32_t src_word = (std::uint32_t(src) << 24) | (std::uint32_t(255 - src) << 16) |
                                         (std::uint32_t(src) << 8) | std::uint32_t(alpha);
          h.draw(full_target(src_word));
          cases.push_back({x, y, src, dst, alpha});
        }
    h.scissor(0, 0, 1024, 1024);
    for (const auto& c : cases) {
      const auto got = h.color(c.x, c.y);
      const int src_a = c.alpha;
      EXPECT_EQ(got.r, blend_expected(mode, c.src, c.dst, c.alpha)) << int(mode) << " " << c.src << " " << c.dst << " " << c.alpha;
      EXPECT_EQ(got.g, blend_expected(mode, 255 - c.src, c.dst, c.alpha));
      EXPECT_EQ(got.b, blend_expected(mode, c.src, c.dst, c.alpha));
      EXPECT_EQ(got.a, blend_expected(mode, src_a, c.dst, c.alpha));
    }
  }
}

// Two Gouraud triangles covering the 64x64 target with random vertex colours (alpha included):
// every row is a long span, so the vector span routine draws them.
std::vector<DeviceTriangle> gradient_target(std::mt19937& rng) {
  std::uniform_int_distribution<std::uint32_t> col(0, 0xFFFFFFFFu);
  const auto a = dv(0, 0, 0, col(rng)), b = dv(64 * 16, 0, 0, col(rng)), c = dv(64 * 16, 64 * 16, 0, col(rng)),
             d = dv(0, 64 * 16, 0, col(rng));
  return {{a, b, c}, {a, c, d}};
}

// Bound: exact equality, per pixel and channel, with the integer formula applied to the source
// colour (the same triangles drawn without blend) and the stored colour, on long spans (the vector
// routine) for every blend mode and write masks; masked channels keep the stored value.
TEST(PixelPipeline, BlendAndMaskOnLongSpans_ExactFormula) {
  std::mt19937 rng(2026);
  for (auto mode : {BlendMode::Off, BlendMode::Alpha, BlendMode::Add, BlendMode::Multiply}) {
    for (unsigned keep : {0u, 0x5u, 0x8u, 0x6u}) {
      const auto dst_tris = gradient_target(rng), src_tris = gradient_target(rng);
      geometry::RenderState plain;
      SimHarness source;  // the source colours alone
      source.clear(0);
      source.state(plain);
      source.draw(src_tris);
      SimHarness h;
      h.clear(0);
      h.state(plain);
      h.draw(dst_tris);
      const auto dst = h.color_bytes();
      geometry::RenderState st;
      st.blend = mode;
      st.mask_r = keep & 1, st.mask_g = keep & 2, st.mask_b = keep & 4, st.mask_a = keep & 8;
      h.state(st);
      h.draw(src_tris);
      const auto src = source.color_bytes(), got = h.color_bytes();
      ASSERT_EQ(got.size(), dst.size());
      int checked = 0;
      for (std::size_t p = 0; p < got.size(); p += 4) {
        const int alpha = src[p + 3];
        for (unsigned c = 0; c < 4; ++c) {
          const int want = (keep >> c) & 1 ? dst[p + c] : blend_expected(mode, src[p + c], dst[p + c], alpha);
          ASSERT_EQ(got[p + c], want) << "mode " << int(mode) << " keep " << keep << " pixel " << p / 4 << " channel "
                                      << c << " src " << int(src[p + c]) << " dst " << int(dst[p + c]) << " alpha "
                                      << alpha;
          ++checked;
        }
      }
      EXPECT_EQ(checked, 64 * 64 * 4);
    }
  }
}

constexpr int kBayer[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};
int dither_expected(int v, int bits, int x, int y, bool dither) {
  if (!dither) return v >> (8 - bits);
  return std::min(255, v + ((kBayer[y & 3][x & 3] << (8 - bits)) >> 4)) >> (8 - bits);
}

// Bound: exact equality with the Bayer formula (screen-indexed, saturating at 255) for all 256
// channel values, in RGB565 and RGBA2222, with DITHER on and off.
TEST(PixelPipeline, DitherAllValues_ExactFormula) {
  for (auto fmt : {protocol::PixelFormat::RGB565, protocol::PixelFormat::RGBA2222}) {
    for (bool dither : {false, true}) {
      SimHarness h({.width = 64, .height = 64, .format = fmt});
      geometry::RenderState st;
      st.gouraud = false;
      st.dither = dither;
      h.state(st);
      // Value v fills the 4x4 block number v (16 x 16 blocks).
      for (int v = 0; v < 256; ++v) {
        const int bx = (v % 16) * 4, by = (v / 16) * 4;
        h.scissor(unsigned(bx), unsigned(by), unsigned(bx + 4), unsigned(by + 4));
        h.draw(full_target((std::uint32_t(v) << 24) | (std::uint32_t(255 - v) << 16) | (std::uint32_t(v) << 8) | std::uint32_t(v)));
      }
      const auto bits = protocol::channel_bits(fmt);
      const auto bytes = h.color_bytes();
      const unsigned bpp = protocol::bytes_per_pixel(fmt);
      for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
          const int v = (y / 4) * 16 + x / 4;
          const std::uint8_t* p = &bytes[(y * 64 + x) * bpp];
          unsigned r, g, b, a = 0;
          if (fmt == protocol::PixelFormat::RGB565) {
            const unsigned w = (unsigned{p[0]} << 8) | p[1];
            r = w >> 11, g = (w >> 5) & 63, b = w & 31;
          } else {
            r = p[0] >> 6, g = (p[0] >> 4) & 3, b = (p[0] >> 2) & 3, a = p[0] & 3;
          }
          ASSERT_EQ(int(r), dither_expected(v, bits.r, x, y, dither)) << x << "," << y;
          ASSERT_EQ(int(g), dither_expected(255 - v, bits.g, x, y, dither)) << x << "," << y;
          ASSERT_EQ(int(b), dither_expected(v, bits.b, x, y, dither)) << x << "," << y;
          if (bits.a) {
            ASSERT_EQ(int(a), dither_expected(v, bits.a, x, y, dither)) << x << "," << y;
          }
        }
    }
  }
}

// Bound: identical bytes for a dithered Gouraud mesh drawn forwards, backwards and with 1 or 3
// threads (the ordered dither depends on the screen position only, the temporal one on the phase
// as well), in RGB565 and RGBA2222; neither dither has an effect on RGBA8888.
TEST(PixelPipeline, DitherIndependentOfOrderAndBands_Identical) {
  std::mt19937 rng(24);
  std::vector<DeviceTriangle> mesh;
  // A non-overlapping grid of Gouraud triangles.
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      const int x0 = i * 128, y0 = j * 128, x1 = x0 + 128, y1 = y0 + 128;
      auto v = [&](int x, int y) { return dv(x, y, 0, rng()); };
      mesh.push_back({v(x0, y0), v(x1, y0), v(x1, y1)});
      mesh.push_back({v(x0, y0), v(x1, y1), v(x0, y1)});
    }
  struct Mode {
    bool temporal;
    unsigned phase;
  };
  for (const Mode mode : {Mode{false, 0}, Mode{true, 0}, Mode{true, 5}, Mode{true, 15}}) {
    geometry::RenderState st;
    st.dither = true;
    st.temporal = mode.temporal;
    st.dither_phase = mode.phase;
    for (auto fmt : {protocol::PixelFormat::RGB565, protocol::PixelFormat::RGBA2222}) {
      std::vector<std::uint8_t> reference;
      for (unsigned threads : {1u, 3u})
        for (bool reversed : {false, true}) {
          SimHarness h({.width = 64, .height = 64, .format = fmt, .threads = threads});
          h.state(st);
          auto tris = mesh;
          if (reversed) std::reverse(tris.begin(), tris.end());
          h.draw(tris);
          if (reference.empty()) reference = h.color_bytes();
          else EXPECT_TRUE(h.color_bytes() == reference) << "temporal " << mode.temporal << " phase " << mode.phase << ", "
                                                         << threads << " threads, reversed " << reversed;
        }
    }
    std::vector<std::uint8_t> without;
    for (bool dither : {false, true}) {
      SimHarness h;
      geometry::RenderState s8 = st;
      s8.dither = dither;
      h.state(s8);
      h.draw(mesh);
      if (!dither) without = h.color_bytes();
      else EXPECT_TRUE(h.color_bytes() == without) << "temporal " << mode.temporal << " phase " << mode.phase;
    }
  }
}

}  // namespace
}  // namespace gpubridge::accuracy
