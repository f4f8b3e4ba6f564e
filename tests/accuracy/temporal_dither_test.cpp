// Hard case 25: the temporal dither (TRI_MODE.TEMPORAL, DITHER_PHASE; docs/protocol.md section
// 11.1). Every frame is bit-exact against the document's integer formula, written here
// independently; the mean of N frames of a flat colour on RGBA2222 lies within the bound the
// document proves, per pixel and channel. (Independence of draw order and bands: pixel_pipeline_test's
// DitherIndependentOfOrderAndBands covers both dithers.)
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdlib>

#include "sim_harness.hpp"

namespace gpubridge::accuracy {
namespace {

using geometry::DeviceTriangle;
using protocol::PixelFormat;

constexpr int kBayer[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};

// The four bits of p in reverse order.
int reverse4(int p) { return ((p & 1) << 3) | ((p & 2) << 1) | ((p & 4) >> 1) | ((p & 8) >> 3); }

// Section 11, temporal dither: c = floor((M·v + floor(M·v / 256) + 16·t + 8) / 256).
int temporal_expected(int v, int bits, int x, int y, int phase) {
  const int m = (1 << bits) - 1, t = kBayer[y & 3][x & 3] ^ reverse4(phase);
  return (m * v + m * v / 256 + 16 * t + 8) / 256;
}

// The four channel values of block v: every channel sees all 256 values over the 256 blocks.
std::array<int, 4> block_values(int v) { return {v, 255 - v, v ^ 0x5A, (v + 128) & 255}; }

// A 64x64 target whose 4x4 block number v (16 x 16 blocks) holds the flat colour block_values(v).
std::vector<std::uint8_t> render_blocks(PixelFormat fmt, const geometry::RenderState& st) {
  SimHarness h({.width = 64, .height = 64, .format = fmt});
  h.state(st);
  for (int v = 0; v < 256; ++v) {
    const int bx = (v % 16) * 4, by = (v / 16) * 4;
    const auto c = block_values(v);
    const std::uint32_t rgba = (std::uint32_t(c[0]) << 24) | (std::uint32_t(c[1]) << 16) | (std::uint32_t(c[2]) << 8) |
                               std::uint32_t(c[3]);
    h.scissor(unsigned(bx), unsigned(by), unsigned(bx + 4), unsigned(by + 4));
    const auto a = dv(0, 0, 0, rgba), b = dv(64 * 16, 0, 0, rgba), cc = dv(64 * 16, 64 * 16, 0, rgba),
               d = dv(0, 64 * 16, 0, rgba);
    const DeviceTriangle tris[] = {{a, b, cc}, {a, cc, d}};
    h.draw(tris);
  }
  EXPECT_EQ(h.device_errors(), 0);
  return h.color_bytes();
}

geometry::RenderState temporal_state(int phase, bool temporal = true) {
  geometry::RenderState st;
  st.gouraud = false;
  st.dither = true;
  st.temporal = temporal;
  st.dither_phase = unsigned(phase);
  return st;
}

// The stored n-bit channels of pixel i.
std::array<int, 4> channels(PixelFormat fmt, const std::vector<std::uint8_t>& bytes, int i) {
  if (fmt == PixelFormat::RGB565) {
    const int w = (bytes[std::size_t(i) * 2] << 8) | bytes[std::size_t(i) * 2 + 1];
    return {w >> 11, (w >> 5) & 63, w & 31, -1};
  }
  const int b = bytes[std::size_t(i)];
  return {b >> 6, (b >> 4) & 3, (b >> 2) & 3, b & 3};
}

// Bound: exact equality with the formula for all 256 values of every channel, all 16 phases, in
// RGB565 and RGBA2222.
TEST(TemporalDither, AllValuesAllPhases_ExactFormula) {
  for (auto fmt : {PixelFormat::RGB565, PixelFormat::RGBA2222}) {
    const auto bits = protocol::channel_bits(fmt);
    const int widths[4] = {bits.r, bits.g, bits.b, bits.a};
    for (int phase = 0; phase < 16; ++phase) {
      const auto bytes = render_blocks(fmt, temporal_state(phase));
      for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
          const auto values = block_values((y / 4) * 16 + x / 4);
          const auto got = channels(fmt, bytes, y * 64 + x);
          for (int c = 0; c < 4; ++c) {
            if (widths[c] == 0) continue;
            ASSERT_EQ(got[c], temporal_expected(values[c], widths[c], x, y, phase))
                << protocol::to_string(fmt) << " phase " << phase << " at " << x << "," << y << " channel " << c
                << " value " << values[c];
          }
        }
    }
  }
}

// Section 11.1's bound for RGBA2222 (stored level c displays as 85·c): for N = 2^k frames whose
// phases form an aligned run {mN .. mN + N - 1}, the mean m_N of one pixel's channel satisfies
//   -85·(1/N - 1/32 + 1/256) < 85·m_N - v <= 85·(1/N - 1/32),
// checked here in integers (times 256·N) for every pixel, channel, value, N and run. One frame's
// aligned 4x4 block satisfies the N = 16 bound as well. The worst case observed at N = 16 must be
// within 0.4 LSB of the bound (the bound is tight), and the ordered dither (TEMPORAL = 0) must break
// it (so the check can fail).
TEST(TemporalDither, MeanOfFramesOfAFlatColour_WithinProvenBound) {
  const auto fmt = PixelFormat::RGBA2222;
  std::vector<std::vector<std::uint8_t>> frames, ordered;
  for (int phase = 0; phase < 16; ++phase) {
    frames.push_back(render_blocks(fmt, temporal_state(phase)));
    ordered.push_back(render_blocks(fmt, temporal_state(phase, false)));
  }
  // e = 256·N·(85·mean - v) = 256·85·sum - 256·N·v; bounds (-85·(256 - 7N), 85·(256 - 8N)].
  auto within = [](long sum, int n, int v) {
    const long e = 256L * 85 * sum - 256L * n * v;
    return -85L * (256 - 7 * n) < e && e <= 85L * (256 - 8 * n);
  };
  auto lsb = [](long sum, int n, int v) { return std::abs(85.0 * double(sum) / n - v); };
  double worst16 = 0, ordered_worst16 = 0;
  for (int i = 0; i < 64 * 64; ++i) {
    const int x = i % 64, y = i / 64;
    const auto values = block_values((y / 4) * 16 + x / 4);
    for (int c = 0; c < 4; ++c) {
      for (int n = 1; n <= 16; n *= 2)
        for (int first = 0; first < 16; first += n) {
          long sum = 0, ordered_sum = 0;
          for (int p = first; p < first + n; ++p) {
            sum += channels(fmt, frames[std::size_t(p)], i)[c];
            ordered_sum += channels(fmt, ordered[std::size_t(p)], i)[c];
          }
          ASSERT_TRUE(within(sum, n, values[c]))
              << "pixel " << x << "," << y << " channel " << c << " value " << values[c] << ": mean of " << n
              << " frames from phase " << first << " is " << 85.0 * double(sum) / n;
          if (n == 16) {
            worst16 = std::max(worst16, lsb(sum, n, values[c]));
            ordered_worst16 = std::max(ordered_worst16, lsb(ordered_sum, n, values[c]));
          }
        }
    }
  }
  // One frame, one aligned 4x4 block (all 16 thresholds): the N = 16 bound.
  for (int phase = 0; phase < 16; ++phase)
    for (int v = 0; v < 256; ++v) {
      const int bx = (v % 16) * 4, by = (v / 16) * 4;
      for (int c = 0; c < 4; ++c) {
        long sum = 0;
        for (int y = by; y < by + 4; ++y)
          for (int x = bx; x < bx + 4; ++x) sum += channels(fmt, frames[std::size_t(phase)], y * 64 + x)[c];
        EXPECT_TRUE(within(sum, 16, block_values(v)[c])) << "phase " << phase << " block " << v << " channel " << c;
      }
    }
  const double bound16 = 85.0 * (1.0 / 16 - 1.0 / 32 + 1.0 / 256);
  EXPECT_GT(worst16, bound16 - 0.4) << "the N = 16 bound is not tight any more";
  EXPECT_GT(ordered_worst16, bound16) << "the ordered dither met the temporal bound: the check cannot fail";
}

}  // namespace
}  // namespace gpubridge::accuracy
