// Register conversions: the snapping tie rule, range limits, NaN/Inf rejection, colours, depth,
// and the per-triangle S/T/Q normalisation (S/Q recovers U within the documented bound).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "gpubridge/geometry/convert.hpp"

namespace gpubridge::geometry {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(Snap, RoundsHalfUp) {
  // x = k/16 + 1/32 is exactly half-way between two 1/16 steps: always rounds towards +inf.
  EXPECT_EQ(*snap_12_4(1.0 / 32), 1);
  EXPECT_EQ(*snap_12_4(-1.0 / 32), 0);
  EXPECT_EQ(*snap_12_4(3.0 / 32), 2);
  EXPECT_EQ(*snap_12_4(-3.0 / 32), -1);
  EXPECT_EQ(*snap_12_4(100.5 + 1.0 / 32), 100 * 16 + 9);
  // Just below a tie rounds down.
  EXPECT_EQ(*snap_12_4(std::nextafter(1.0 / 32, 0.0)), 0);
  EXPECT_EQ(*snap_12_4(-2.0), -32);
  EXPECT_EQ(*snap_12_4(0.0), 0);
}

TEST(Snap, RangeLimitsAreThe12_4Range) {
  EXPECT_EQ(*snap_12_4(2047.9375), 32767);
  EXPECT_EQ(*snap_12_4(-2048.0), -32768);
  EXPECT_EQ(*snap_12_4(2047.9375 + 1.0 / 64), 32767);   // still rounds down to the top value
  EXPECT_FALSE(snap_12_4(2047.96875));                  // tie rounds up to 32768: out of range
  EXPECT_EQ(*snap_12_4(-2048.03125), -32768);           // tie rounds up into range
  EXPECT_FALSE(snap_12_4(-2048.04));
  EXPECT_FALSE(snap_12_4(1e300));
  const auto e = snap_12_4(5000, "draws[0].vertices[1].x");
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().message.find("draws[0].vertices[1].x"), std::string::npos);
  EXPECT_NE(e.error().message.find("12.4"), std::string::npos);
}

TEST(Convert, RejectsNaNAndInf) {
  for (double bad : {kNaN, kInf, -kInf}) {
    EXPECT_FALSE(snap_12_4(bad));
    EXPECT_FALSE(depth_to_z24(bad));
    EXPECT_FALSE(unit_to_u8(bad));
    EXPECT_FALSE(color_to_rgba8({0.5, bad, 0.5, 1}));
  }
  const auto e = snap_12_4(kNaN, "x");
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().message.find("NaN"), std::string::npos);
}

TEST(Convert, DepthAndColour) {
  EXPECT_EQ(*depth_to_z24(0.0), 0u);
  EXPECT_EQ(*depth_to_z24(1.0), 0xFFFFFFu);
  EXPECT_EQ(*depth_to_z24(2.0), 0xFFFFFFu);
  EXPECT_EQ(*depth_to_z24(0.5), 8388608u);  // 0.5·16777215 + 0.5 = 8388608.0
  EXPECT_EQ(*depth_to_z24(-1e-12), 0u);     // clipping round-off
  EXPECT_FALSE(depth_to_z24(-0.5));
  EXPECT_EQ(*unit_to_u8(0.5), 128);         // round(127.5) = 128
  EXPECT_EQ(*unit_to_u8(-3), 0);
  EXPECT_EQ(*unit_to_u8(7), 255);
  EXPECT_EQ(*color_to_rgba8({1, 0, 0.2, 0.6}), 0xFF003399u);
}

TEST(Convert, TextureOffsetPerWrapMode) {
  EXPECT_EQ(texture_offset(-2.5, protocol::Wrap::Repeat), -3);
  EXPECT_EQ(texture_offset(3.7, protocol::Wrap::Repeat), 3);
  EXPECT_EQ(texture_offset(3.7, protocol::Wrap::Mirror), 2);
  EXPECT_EQ(texture_offset(-0.5, protocol::Wrap::Mirror), -2);
  EXPECT_EQ(texture_offset(3.7, protocol::Wrap::Clamp), 0);
}

std::array<ScreenVertex, 3> random_triangle(std::mt19937_64& rng, double max_w_ratio, double uv_range) {
  std::uniform_real_distribution<double> pos(-2000, 2000), unit(0, 1), ratio(0, std::log(max_w_ratio));
  std::uniform_real_distribution<double> uv(-uv_range, uv_range);
  const double base_u = uv(rng), base_v = uv(rng);
  std::array<ScreenVertex, 3> t;
  for (auto& v : t) {
    v.x = pos(rng);
    v.y = pos(rng);
    v.z = unit(rng);
    v.w = 0.5 * std::exp(ratio(rng));
    v.color = {unit(rng), unit(rng), unit(rng), unit(rng)};
    v.uv = {base_u + 4 * unit(rng) - 2, base_v + 4 * unit(rng) - 2};
  }
  return t;
}

TEST(Normalise, LargestQIsFullScaleAndRatiosArePreserved) {
  std::mt19937_64 rng(7);
  for (int n = 0; n < 2000; ++n) {
    const auto t = random_triangle(rng, 1000, 100);
    const auto d = convert_triangle(t, {});
    ASSERT_TRUE(d) << d.error().message;
    std::uint32_t qmax = 0;
    int imax = 0;
    for (int i = 0; i < 3; ++i)
      if ((*d)[i].q > qmax) qmax = (*d)[i].q, imax = i;
    EXPECT_EQ(qmax, 0xFFFFFFFFu);
    EXPECT_LE(t[imax].w, std::min({t[0].w, t[1].w, t[2].w}));
    for (int i = 0; i < 3; ++i) {
      // Q_i / Q_max = w_max_q / w_i within the rounding of Q_i (±0.5 of 2^32 − 1).
      const double expect = t[imax].w / t[i].w * 4294967295.0;
      EXPECT_LE(std::abs((*d)[i].q - expect), 0.5 + 1e-5) << n;
    }
  }
}

TEST(Normalise, SOverQRecoversUWithinBound) {
  // Documented bound: |S·2^8/Q + u_off − u| ≤ 128/Q texture widths (S rounding, ±0.5 LSB of 2^-24,
  // divided by Q/2^32), for every wrap mode.
  std::mt19937_64 rng(11);
  for (auto wrap : {protocol::Wrap::Repeat, protocol::Wrap::Mirror, protocol::Wrap::Clamp}) {
    for (int n = 0; n < 2000; ++n) {
      const auto t = random_triangle(rng, 64, wrap == protocol::Wrap::Clamp ? 50 : 1e4);
      const TexAddressing tex{wrap, wrap};
      const auto d = convert_triangle(t, tex);
      ASSERT_TRUE(d) << d.error().message;
      const double uoff = texture_offset(std::min({t[0].uv.x, t[1].uv.x, t[2].uv.x}), wrap);
      const double voff = texture_offset(std::min({t[0].uv.y, t[1].uv.y, t[2].uv.y}), wrap);
      for (int i = 0; i < 3; ++i) {
        const double q = (*d)[i].q;
        ASSERT_GT(q, 0);
        const double bound = 128.0 / q * (1 + 1e-9) + 1e-12;
        EXPECT_LE(std::abs((*d)[i].s * 256.0 / q + uoff - t[i].uv.x), bound);
        EXPECT_LE(std::abs((*d)[i].t * 256.0 / q + voff - t[i].uv.y), bound);
      }
    }
  }
}

TEST(Normalise, RepeatOffsetKeepsSmallRangeForLargeCoordinates) {
  std::array<ScreenVertex, 3> t;
  t[0] = {0, 0, 0, 1, {1, 1, 1, 1}, {1000.25, -5000.5}};
  t[1] = {10, 0, 0, 1, {1, 1, 1, 1}, {1001.25, -5000.5}};
  t[2] = {0, 10, 0, 1, {1, 1, 1, 1}, {1000.25, -4999.5}};
  const auto d = convert_triangle(t, {});
  ASSERT_TRUE(d);
  // u_off = 1000, v_off = -5001: u − u_off = 0.25, 1.25; v − v_off = 0.5, 1.5 in 8.24 with Q = 2^32 − 1.
  EXPECT_NEAR((*d)[0].s, 0.25 * 16777216, 1);
  EXPECT_NEAR((*d)[1].s, 1.25 * 16777216, 1);
  EXPECT_NEAR((*d)[0].t, 0.5 * 16777216, 1);
  EXPECT_NEAR((*d)[2].t, 1.5 * 16777216, 1);
  // The same coordinates with CLAMP cannot be represented: a clear error.
  const auto c = convert_triangle(t, TexAddressing{protocol::Wrap::Clamp, protocol::Wrap::Clamp});
  ASSERT_FALSE(c);
  EXPECT_NE(c.error().message.find("128"), std::string::npos);
}

TEST(Normalise, RejectsBadW) {
  std::array<ScreenVertex, 3> t{};
  t[1].x = 1;
  t[2].y = 1;
  for (double w : {0.0, -1.0, kNaN, kInf, 1e-320}) {
    t[2].w = w;
    EXPECT_FALSE(convert_triangle(t, {})) << w;
  }
  t[2].w = 1;
  t[1].uv.x = kNaN;
  EXPECT_FALSE(convert_triangle(t, {}));
}

TEST(Words, VertexAndColourPacking) {
  DeviceVertex v;
  v.x = -16;
  v.y = 32;
  v.z = 0xABCDEF;
  v.rgba = 0x11223344;
  v.q = 0x80000000u;
  v.s = -1;
  v.t = 0x01000000;
  EXPECT_EQ(vertex_word(v), 0x00ABCDEF'0020FFF0ull);
  EXPECT_EQ(color_word(v), 0x80000000'11223344ull);
  EXPECT_EQ(texcoord_word(v), 0xFFFFFFFF'01000000ull);
}

}  // namespace
}  // namespace gpubridge::geometry
