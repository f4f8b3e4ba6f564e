// The pixel pipeline (docs/protocol.md section 11): depth functions, blend formulas at corner
// values, quantisation and dither in RGB565 / RGBA2222, write masks. Expected values are computed
// here from the document's formulas.
#include <gtest/gtest.h>

#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

using namespace protocol;

unsigned ref_div255(unsigned x) { return (x + 128 + ((x + 128) >> 8)) >> 8; }
constexpr int kBayer[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};
unsigned ref_dither(unsigned v, unsigned n, int x, int y) {
  const unsigned t = v + ((unsigned(kBayer[y & 3][x & 3]) << (8 - n)) >> 4);
  return (t > 255 ? 255 : t) >> (8 - n);
}

// Temporal dither (TEMPORAL = 1): threshold B ^ reverse4(phase), levels scaled to 0..2^n - 1.
unsigned ref_temporal(unsigned v, unsigned n, int x, int y, unsigned phase) {
  const unsigned rev = ((phase & 1) << 3) | ((phase & 2) << 1) | ((phase & 4) >> 1) | ((phase & 8) >> 3);
  const unsigned t = unsigned(kBayer[y & 3][x & 3]) ^ rev;
  const unsigned m = (1u << n) - 1;
  return (m * v + ((m * v) >> 8) + 16 * t + 8) >> 8;
}
std::uint64_t temporal_mode(unsigned phase) { return (1u << 9) | (1u << 15) | (std::uint64_t{phase} << 16); }

// A flat full-canvas quad (two triangles) with colour c and depth z.
void quad(Canvas& c, std::uint32_t rgba, std::uint32_t z = 0) {
  const int W = static_cast<int>(c.width) * 16, H = static_cast<int>(c.height) * 16;
  c.tri(0, 0, W, 0, 0, H, rgba, rgba, rgba, z, z, z);
  c.tri(W, 0, W, H, 0, H, rgba, rgba, rgba, z, z, z);
}

TEST(SimPipeline, DepthFunctions) {
  const struct {
    DepthFunc f;
    bool lt, eq, gt;
  } cases[] = {{DepthFunc::Never, false, false, false},  {DepthFunc::Less, true, false, false},
               {DepthFunc::Equal, false, true, false},   {DepthFunc::LessEqual, true, true, false},
               {DepthFunc::Greater, false, false, true}, {DepthFunc::NotEqual, true, false, true},
               {DepthFunc::GreaterEqual, false, true, true}, {DepthFunc::Always, true, true, true}};
  for (const auto& cs : cases) {
    const std::uint32_t zs[3] = {0x7FFFFF, 0x800000, 0x800001};
    const bool pass[3] = {cs.lt, cs.eq, cs.gt};
    for (int i = 0; i < 3; ++i) {
      Canvas c(4, 4);
      w(*c.dev, Reg::CLEAR_DEPTH, 0x800000);
      w(*c.dev, Reg::CLEAR_Z, 0);
      w(*c.dev, Reg::TRI_MODE, 4 | (unsigned(cs.f) << 3) | (1u << 6));  // test + write
      quad(c, 0xFFFFFFFF, zs[i]);
      EXPECT_EQ(c.rgba(1, 1), pass[i] ? 0xFFFFFFFFu : 0u) << int(cs.f) << " " << i;
      EXPECT_EQ(c.depth(1, 1), pass[i] ? zs[i] : 0x800000u) << int(cs.f) << " " << i;
    }
  }
}

TEST(SimPipeline, DepthWriteWithoutTestAndZBitsKnob) {
  Canvas c(4, 4);
  w(*c.dev, Reg::TRI_MODE, 1u << 6);
  quad(c, 0x10203040, 0xABCDEF);
  EXPECT_EQ(c.depth(2, 2), 0xABCDEFu);
  DeviceOptions o;
  o.accuracy.z_bits = 16;
  Canvas k(4, 4, 0, o);
  w(*k.dev, Reg::TRI_MODE, 1u << 6);
  quad(k, 0x10203040, 0xABCDEF);
  EXPECT_EQ(k.depth(2, 2), 0xABCD00u);
}

TEST(SimPipeline, BlendCornerValues) {
  const std::uint32_t srcs[] = {0x00000000, 0xFFFFFFFF, 0x80402000, 0x804020FF, 0xC0C0C07F};
  const std::uint32_t dsts[] = {0x00000000, 0xFFFFFFFF, 0x11223344};
  for (unsigned mode = 1; mode <= 3; ++mode)
    for (std::uint32_t src : srcs)
      for (std::uint32_t dst : dsts) {
        Canvas c(4, 4);
        w(*c.dev, Reg::CLEAR_COLOR, dst);
        w(*c.dev, Reg::CLEAR, 0);
        w(*c.dev, Reg::TRI_MODE, mode << 7);
        quad(c, src);
        std::uint32_t expect = 0;
        const unsigned a = src & 255;
        for (int sh = 24; sh >= 0; sh -= 8) {
          const unsigned s = (src >> sh) & 255, d = (dst >> sh) & 255;
          unsigned v = 0;
          if (mode == 1) v = ref_div255(s * a + d * (255 - a));
          if (mode == 2) v = std::min(255u, s + d);
          if (mode == 3) v = ref_div255(s * d);
          expect |= v << sh;
        }
        EXPECT_EQ(c.rgba(2, 1), expect) << "mode " << mode << std::hex << " src " << src << " dst " << dst;
      }
  // The corner identities the formulas must give.
  EXPECT_EQ(ref_div255(255 * 255), 255u);
  EXPECT_EQ(ref_div255(0), 0u);
}

TEST(SimPipeline, DitherRgba2222FollowsBayerFormula) {
  for (std::uint32_t v : {0x00u, 0x30u, 0x55u, 0x7Fu, 0xC8u, 0xFFu}) {
    Canvas c(8, 8, 2);
    w(*c.dev, Reg::TRI_MODE, 1u << 9);
    const std::uint32_t rgba = (v << 24) | (v << 16) | (v << 8) | v;
    quad(c, rgba);
    Canvas plain(8, 8, 2);
    quad(plain, rgba);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        const unsigned q = ref_dither(v, 2, x, y);
        EXPECT_EQ(c.px(x, y)[0], (q << 6) | (q << 4) | (q << 2) | q) << v << " " << x << "," << y;
        const unsigned t = v >> 6;
        EXPECT_EQ(plain.px(x, y)[0], (t << 6) | (t << 4) | (t << 2) | t);
      }
  }
}

TEST(SimPipeline, DitherRgb565FollowsBayerFormula) {
  Canvas c(8, 8, 1);
  w(*c.dev, Reg::TRI_MODE, 1u << 9);
  quad(c, 0x83417EFF);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const unsigned expect = (ref_dither(0x83, 5, x, y) << 11) | (ref_dither(0x41, 6, x, y) << 5) | ref_dither(0x7E, 5, x, y);
      EXPECT_EQ((unsigned{c.px(x, y)[0]} << 8) | c.px(x, y)[1], expect) << x << "," << y;
    }
}

TEST(SimPipeline, TemporalDitherRgba2222FollowsFormula) {
  for (unsigned phase = 0; phase < 16; ++phase)
    for (std::uint32_t v : {0x00u, 0x01u, 0x2Au, 0x55u, 0x80u, 0xAAu, 0xFEu, 0xFFu}) {
      Canvas c(8, 8, 2);
      w(*c.dev, Reg::TRI_MODE, temporal_mode(phase));
      quad(c, (v << 24) | ((255 - v) << 16) | (v << 8) | (v ^ 0x5A));
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
          const unsigned expect = (ref_temporal(v, 2, x, y, phase) << 6) | (ref_temporal(255 - v, 2, x, y, phase) << 4) |
                                  (ref_temporal(v, 2, x, y, phase) << 2) | ref_temporal(v ^ 0x5A, 2, x, y, phase);
          ASSERT_EQ(c.px(x, y)[0], expect) << "v " << v << " phase " << phase << " at " << x << "," << y;
        }
    }
  // The end points are fixed in every phase: 0 stays 0 and 255 stays 3 (no saturation needed).
  for (unsigned phase = 0; phase < 16; ++phase)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        EXPECT_EQ(ref_temporal(0, 2, x, y, phase), 0u);
        EXPECT_EQ(ref_temporal(255, 2, x, y, phase), 3u);
      }
}

TEST(SimPipeline, TemporalDitherRgb565FollowsFormula) {
  for (unsigned phase : {0u, 1u, 6u, 15u}) {
    Canvas c(8, 8, 1);
    w(*c.dev, Reg::TRI_MODE, temporal_mode(phase));
    quad(c, 0x83417EFF);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        const unsigned expect = (ref_temporal(0x83, 5, x, y, phase) << 11) | (ref_temporal(0x41, 6, x, y, phase) << 5) |
                                ref_temporal(0x7E, 5, x, y, phase);
        EXPECT_EQ((unsigned{c.px(x, y)[0]} << 8) | c.px(x, y)[1], expect) << phase << " at " << x << "," << y;
      }
  }
}

// TEMPORAL without DITHER has no effect (truncation), and the phase alone changes nothing.
TEST(SimPipeline, TemporalWithoutDitherTruncates) {
  Canvas c(8, 8, 2), ordered(8, 8, 2);
  w(*c.dev, Reg::TRI_MODE, temporal_mode(9) & ~std::uint64_t{1u << 9});
  quad(c, 0x80808080);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) EXPECT_EQ(c.px(x, y)[0], 0xAA) << x << "," << y;
  w(*ordered.dev, Reg::TRI_MODE, (1u << 9) | (std::uint64_t{9} << 16));  // DITHER + phase, TEMPORAL = 0
  quad(ordered, 0x80808080);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const unsigned q = ref_dither(0x80, 2, x, y);
      EXPECT_EQ(ordered.px(x, y)[0], (q << 6) | (q << 4) | (q << 2) | q) << x << "," << y;
    }
}

TEST(SimPipeline, WriteMasks) {
  Canvas c(4, 4);
  w(*c.dev, Reg::CLEAR_COLOR, 0x11223344);
  w(*c.dev, Reg::CLEAR, 0);
  w(*c.dev, Reg::TRI_MODE, (1u << 11) | (1u << 13));  // keep G and A
  quad(c, 0xAABBCCDD);
  EXPECT_EQ(c.rgba(1, 1), 0xAA22CC44u);

  Canvas s(4, 4, 1);
  w(*s.dev, Reg::CLEAR_COLOR, 0xFFFFFFFF);
  w(*s.dev, Reg::CLEAR, 0);
  w(*s.dev, Reg::TRI_MODE, 1u << 10);  // keep R
  quad(s, 0x00000000);
  EXPECT_EQ((unsigned{s.px(1, 1)[0]} << 8) | s.px(1, 1)[1], 31u << 11);

  // Everything masked and no Z write: nothing changes.
  Canvas n(4, 4);
  w(*n.dev, Reg::TRI_MODE, 15u << 10);
  quad(n, 0xFFFFFFFF);
  EXPECT_EQ(n.count_nonzero(), 0u);
}

}  // namespace
}  // namespace gpubridge::sim::test
