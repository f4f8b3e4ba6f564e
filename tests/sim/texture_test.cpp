// The texture unit (docs/protocol.md section 10) on a tiny 8x8 texture: every pixel is compared
// with a value derived here from the document's formulas (reciprocal table + Newton-Raphson,
// texel coordinates, wrap modes, nearest / bilinear weights, combine), written independently of
// the simulator. Covers the affine path (all Q equal) and the perspective path.
#include <gtest/gtest.h>

#include <bit>
#include <random>

#include "reciprocal.hpp"
#include "reference.hpp"
#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

using namespace protocol;

constexpr std::uint32_t kTexBase = 0x200000;
constexpr unsigned kLog2 = 3, kSize = 8;

std::array<std::uint8_t, 4> texel(unsigned i, unsigned j) {
  return {static_cast<std::uint8_t>(i * 32 + 7), static_cast<std::uint8_t>(j * 32 + 3),
          static_cast<std::uint8_t>((i ^ j) * 16), static_cast<std::uint8_t>(255 - i * j)};
}

// Section 10.1, b = 10, k = 1.
void ref_recip(std::uint32_t q, std::uint64_t& y, unsigned& n) {
  n = static_cast<unsigned>(std::countl_zero(q));
  const std::uint64_t m = std::uint64_t{q} << n;
  const std::uint64_t i = (m >> 21) & 1023;
  const std::uint64_t den = 2048 + 2 * i + 1;
  y = ((std::uint64_t{1} << 44) + den) / (2 * den);
  const std::uint64_t p = m * y;
  const std::uint64_t t = (~p + 1) >> 32;
  const unsigned __int128 yt = (static_cast<unsigned __int128>(y) * t) >> 31;
  y = yt > 0xFFFFFFFFu ? 0xFFFFFFFFu : static_cast<std::uint64_t>(yt);
}

std::int64_t ref_wrap(std::int64_t i, unsigned mode) {
  const std::int64_t W = kSize;
  if (mode == 1) return i < 0 ? 0 : (i > W - 1 ? W - 1 : i);
  if (mode == 2) {
    const std::int64_t k = i & (2 * W - 1);
    return k < W ? k : 2 * W - 1 - k;
  }
  return i & (W - 1);
}

std::array<unsigned, 4> ref_sample(std::int32_t s, std::int32_t t, std::uint32_t q, unsigned ws, unsigned wt,
                                   bool bilinear) {
  std::int64_t tu = 0, tv = 0;
  if (q != 0) {
    std::uint64_t y;
    unsigned n;
    ref_recip(q, y, n);
    tu = (std::int64_t{s} * static_cast<std::int64_t>(y)) >> (43 - n - kLog2);
    tv = (std::int64_t{t} * static_cast<std::int64_t>(y)) >> (43 - n - kLog2);
  }
  auto fetch = [&](std::int64_t i, std::int64_t j) {
    const auto c = texel(static_cast<unsigned>(ref_wrap(i, ws)), static_cast<unsigned>(ref_wrap(j, wt)));
    return std::array<unsigned, 4>{c[0], c[1], c[2], c[3]};
  };
  if (!bilinear) return fetch(tu >> 12, tv >> 12);
  const std::int64_t u = tu - 2048, v = tv - 2048;
  const std::int64_t i0 = u >> 12, j0 = v >> 12;
  const unsigned fu = (u >> 4) & 255, fv = (v >> 4) & 255;
  const auto c00 = fetch(i0, j0), c10 = fetch(i0 + 1, j0), c01 = fetch(i0, j0 + 1), c11 = fetch(i0 + 1, j0 + 1);
  std::array<unsigned, 4> out{};
  for (int k = 0; k < 4; ++k)
    out[k] = (c00[k] * (256 - fu) * (256 - fv) + c10[k] * fu * (256 - fv) + c01[k] * (256 - fu) * fv +
              c11[k] * fu * fv + 32768) >> 16;
  return out;
}

struct TexVertex {
  int x, y;
  std::int32_t s, t;
  std::uint32_t q;
};

void upload_texture(Device& d) {
  auto mem = d.memory();
  for (unsigned j = 0; j < kSize; ++j)
    for (unsigned i = 0; i < kSize; ++i) {
      const auto c = texel(i, j);
      std::copy(c.begin(), c.end(), mem.begin() + kTexBase + (j * kSize + i) * 4);
    }
}

void check_triangle(const TexVertex (&v)[3], unsigned ws, unsigned wt, bool bilinear, bool modulate,
                    int size = 24) {
  Canvas c(size, size);
  upload_texture(*c.dev);
  w(*c.dev, Reg::TEX_BASE, kTexBase);
  w(*c.dev, Reg::TEX_FMT, (std::uint64_t{bilinear} << 12) | (wt << 10) | (ws << 8) | (kLog2 << 4) | kLog2);
  w(*c.dev, Reg::TRI_MODE, 2u | (modulate ? 0u : 1u << 14));
  const std::uint32_t vc = 0xC08040FF;
  for (const auto& p : v) {
    w(*c.dev, Reg::COLOR, color(vc, p.q));
    w(*c.dev, Reg::TEXCOORD, (std::uint64_t{static_cast<std::uint32_t>(p.s)} << 32) | static_cast<std::uint32_t>(p.t));
    w(*c.dev, Reg::VERTEX, vtx(p.x, p.y));
  }
  const ref::P P[3] = {{v[0].x, v[0].y}, {v[1].x, v[1].y}, {v[2].x, v[2].y}};
  unsigned covered = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const ref::Bary b = ref::sample(P[0], P[1], P[2], x, y);
      if (!b.covered) continue;
      ++covered;
      const auto s = static_cast<std::int32_t>(ref::interpolate(b, {v[0].s, v[1].s, v[2].s}));
      const auto t = static_cast<std::int32_t>(ref::interpolate(b, {v[0].t, v[1].t, v[2].t}));
      const auto q = static_cast<std::uint32_t>(ref::interpolate(b, {v[0].q, v[1].q, v[2].q}));
      auto e = ref_sample(s, t, q, ws, wt, bilinear);
      if (modulate) {
        const unsigned vcol[4] = {vc >> 24, (vc >> 16) & 255, (vc >> 8) & 255, vc & 255};
        for (int k = 0; k < 4; ++k) {
          const unsigned xx = e[k] * vcol[k];
          e[k] = (xx + 128 + ((xx + 128) >> 8)) >> 8;
        }
      }
      const std::uint32_t expect = (e[0] << 24) | (e[1] << 16) | (e[2] << 8) | e[3];
      ASSERT_EQ(c.rgba(x, y), expect) << "pixel " << x << "," << y << " wrap " << ws << "/" << wt << " bilinear "
                                      << bilinear;
    }
  EXPECT_GT(covered, 50u);
}

TEST(SimTexture, AddressModesNearestAndBilinearAffine) {
  // All Q equal (affine path); coordinates run from -1.3 to +2.2 texture widths so every wrap
  // mode's negative and beyond-the-edge cases are hit.
  const std::uint32_t q = 0xC0000000u;  // Q = 0.75
  auto st = [&](double u) { return static_cast<std::int32_t>(u * 0.75 * (1 << 24)); };
  const TexVertex v[3] = {{8, 8, st(-1.3), st(-0.9), q}, {23 * 16, 10, st(2.2), st(-1.1), q}, {20, 23 * 16, st(-1.0), st(2.1), q}};
  for (unsigned ws = 0; ws < 3; ++ws)
    for (unsigned wt = 0; wt < 3; ++wt)
      for (bool bil : {false, true}) check_triangle(v, ws, wt, bil, false);
}

TEST(SimTexture, PerspectiveAndModulate) {
  std::mt19937 rng(77);
  std::uniform_int_distribution<std::uint32_t> qd(0x08000000u, 0xFFFFFFFFu);
  std::uniform_int_distribution<std::int32_t> sd(-(3 << 24), 3 << 24);
  for (int iter = 0; iter < 6; ++iter) {
    const TexVertex v[3] = {{0, 0, sd(rng), sd(rng), qd(rng)},
                            {24 * 16, 3 * 16, sd(rng), sd(rng), qd(rng)},
                            {5 * 16, 24 * 16, sd(rng), sd(rng), qd(rng)}};
    check_triangle(v, iter % 3, (iter + 1) % 3, iter % 2 == 0, iter % 3 == 0);
  }
}

// Q constant along x (two vertices on one row with equal Q), varying along y: the span routine
// computes one reciprocal a span for such triangles; every pixel must still be the reference's.
// Wide rows (up to 90 pixels) so that the spans run whole chunks of eight and tails.
TEST(SimTexture, PerspectiveQConstantAlongRows) {
  std::mt19937 rng(1717);
  std::uniform_int_distribution<std::uint32_t> qd(0x01000000u, 0xFFFFFFFFu);
  std::uniform_int_distribution<std::int32_t> sd(-(3 << 24), 3 << 24);
  for (int iter = 0; iter < 6; ++iter) {
    const std::uint32_t q_top = qd(rng), q_bottom = qd(rng);
    const bool top_edge = iter % 2 == 0;  // the equal-Q edge on the first or on the last row
    const int ye = top_edge ? 2 * 16 : 94 * 16, yo = top_edge ? 94 * 16 : 2 * 16;
    const TexVertex v[3] = {{1 * 16, ye, sd(rng), sd(rng), q_top},
                            {95 * 16, ye, sd(rng), sd(rng), q_top},
                            {(30 + 7 * iter) * 16, yo, sd(rng), sd(rng), q_bottom}};
    // Wraps (0, 0) bilinear first: the vector routines' specialised fetch (RGBA8888, repeat, bilinear).
    check_triangle(v, iter % 3, (iter / 2) % 3, iter % 3 != 1, iter % 2 == 1, 96);
  }
}

// The reciprocal unit (section 10.1) for every table size and step count the knobs allow, against
// the document's formula in 128-bit arithmetic: the unit's Newton-Raphson step multiplies in 64
// bits, which is exact only because y and t both stay below 2^32.
TEST(SimTexture, ReciprocalMatchesWideArithmetic) {
  std::mt19937 rng(10);
  std::vector<std::uint32_t> qs = {1u, 2u, 3u, 0x7FFFFFFFu, 0x80000000u, 0x80000001u, 0xFFFFFFFEu, 0xFFFFFFFFu};
  for (unsigned b = 0; b < 32; ++b) {
    qs.push_back(1u << b);
    qs.push_back((1u << b) | ((1u << b) - 1));  // all ones below bit b
  }
  for (int k = 0; k < 4000; ++k) qs.push_back(rng() >> (rng() % 32) | 1u);
  for (unsigned bits = 1; bits <= 16; ++bits)
    for (unsigned steps = 0; steps <= 4; ++steps) {
      const ReciprocalUnit unit(bits, steps);
      for (const std::uint32_t q : qs) {
        const unsigned n = static_cast<unsigned>(std::countl_zero(q));
        const unsigned __int128 m = static_cast<unsigned __int128>(q) << n;
        const unsigned __int128 i = (m >> (31 - bits)) & ((1u << bits) - 1);
        const unsigned __int128 den = (static_cast<unsigned __int128>(1) << (bits + 1)) + 2 * i + 1;
        unsigned __int128 y = ((static_cast<unsigned __int128>(1) << (bits + 34)) + den) / (2 * den);
        if (y > 0xFFFFFFFFu) y = 0xFFFFFFFFu;
        for (unsigned s = 0; s < steps; ++s) {
          const unsigned __int128 p = (m * y) & ~std::uint64_t{0};
          const unsigned __int128 t = ((static_cast<unsigned __int128>(1) << 64) - p) & ~std::uint64_t{0};
          y = (y * (t >> 32)) >> 31;
          if (y > 0xFFFFFFFFu) y = 0xFFFFFFFFu;
        }
        const Reciprocal r = unit(q);
        ASSERT_EQ(r.n, n) << "q " << q;
        ASSERT_EQ(r.y, static_cast<std::uint32_t>(y)) << "q " << q << " bits " << bits << " steps " << steps;
      }
    }
}

TEST(SimTexture, ZeroQSamplesTexelZero) {
  const TexVertex v[3] = {{0, 0, 1 << 24, 1 << 24, 0}, {24 * 16, 0, 1 << 23, 1 << 22, 0}, {0, 24 * 16, 5, 7, 0}};
  check_triangle(v, 0, 0, false, false);
}

}  // namespace
}  // namespace gpubridge::sim::test
