// Hard cases 18-21: texture coordinates (1/W extremes, Q = 0, affine equivalence, reciprocal
// accuracy over every table interval, wrap seams). Texel positions are measured from the written
// colour with the probe texture (texel_probe.hpp), to 1/256 texel, without simulator internals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "gpubridge/accuracy/texel_probe.hpp"
#include "sim_harness.hpp"

namespace gpubridge::accuracy {
namespace {

using geometry::DeviceTriangle;
constexpr unsigned kLog2W = 10, kLog2H = 3, kW = 1u << kLog2W, kH = 1u << kLog2H;
// The probe reads the position to within 1/512 texel (the 8-bit bilinear weight).
constexpr double kProbeResolution = 1.0 / 512;

geometry::RenderState textured_decal() {
  geometry::RenderState st;
  st.textured = true;
  st.tex_decal = true;
  return st;
}

void bind_probe(SimHarness& h) {
  h.texture(make_probe_texture(kLog2W, kLog2H), {.width = kW, .height = kH, .bilinear = true});
  h.state(textured_decal());
}

// docs/protocol.md section 15 with the register values as the reference, per axis of size W at a
// pixel whose exact interpolated q is `q`: S and Q are each rounded once to an integer by the
// interpolator (+-1/2 unit: W * 128 / q and |u| / (2q) texels), the reciprocal's relative error
// 2^-22 times |u|, the final floor to 1/4096 texel, plus the probe resolution.
double texel_bound(double u_texels, double q, unsigned size) {
  return (size * 128.0 + 0.5 * std::fabs(u_texels)) / q + std::fabs(u_texels) * std::ldexp(1.0, -22) + 1.0 / 4096 +
         kProbeResolution + 1e-9;
}

struct TexelError {
  double worst_excess = -1;  // max over pixels of (error - bound); <= 0 means within bound
  double worst = 0;
  int pixels = 0;
};

TexelError measure(SimHarness& h, std::span<const DeviceTriangle> tris) {
  TexelError e;
  for (const auto& t : tris) {
    for (const auto& s : rasterize(to_fixed(t), h.full_rect())) {
      const auto c = h.color(s.x, s.y);
      const double eu = s.u() * kW, ev = s.v() * kH;
      const auto ru = read_probe_axis(c.r, c.g, eu, kW), rv = read_probe_axis(c.b, c.a, ev, kH);
      const double err_u = std::fabs(ru.position - eu), err_v = std::fabs(rv.position - ev);
      e.worst = std::max({e.worst, err_u, err_v});
      e.worst_excess = std::max({e.worst_excess, err_u - texel_bound(eu, s.q, kW), err_v - texel_bound(ev, s.q, kH)});
      ++e.pixels;
    }
  }
  return e;
}

// A quad of two triangles over [x0, x1) x [y0, y1) (whole pixels) with per-corner q and u, v.
std::vector<DeviceTriangle> quad(int x0, int y0, int x1, int y1, std::array<std::uint32_t, 4> q,
                                 std::array<double, 4> u, std::array<double, 4> v) {
  const int xs[4] = {x0, x1, x1, x0}, ys[4] = {y0, y0, y1, y1};
  geometry::DeviceVertex c[4];
  for (int i = 0; i < 4; ++i) {
    // S = U * Q in s8.24: s = u * q / 256 (register units).
    c[i] = dv(xs[i] * 16, ys[i] * 16, 0, 0xFFFFFFFF, q[i], std::int32_t(std::lround(u[i] * q[i] / 256.0)),
              std::int32_t(std::lround(v[i] * q[i] / 256.0)));
  }
  return {{c[0], c[1], c[2]}, {c[0], c[2], c[3]}};
}

// Bound: texel error within the section-15 bound (texel_bound) for q at every exponent of the
// 32-bit range (W tiny to W huge, a W ratio of 2 inside each quad). Exponents whose bound exceeds 64
// texels (q < 2^11: the registers cannot express the coordinate) are drawn but not judged: the
// probe searches kProbeWindow = 100 texels around the reference.
TEST(Texture, OneOverWAllExponents_WithinReciprocalBound) {
  SimHarness h({.width = 64, .height = 64});
  bind_probe(h);
  std::vector<DeviceTriangle> tris;
  for (int n = 0; n < 32; ++n) {
    const std::uint32_t hi = n == 0 ? 0xFFFFFFFFu : (2u << (31 - n)) - 1, lo = std::max(1u, hi >> 1);
    const int x = (n % 8) * 8, y = (n / 8) * 8;
    for (auto& t : quad(x, y, x + 8, y + 8, {hi, lo, hi, lo}, {0.1, 0.9, 0.3, 0.05}, {0.2, 0.4, 0.9, 0.6})) tris.push_back(t);
  }
  h.draw(tris);
  int pixels = 0;
  for (int n = 0; n <= 20; ++n) {
    const auto e = measure(h, std::span(tris).subspan(std::size_t(n) * 2, 2));
    EXPECT_LE(e.worst_excess, 0.0) << "exponent " << n << ": worst texel error " << e.worst;
    pixels += e.pixels;
  }
  EXPECT_EQ(pixels, 21 * 64);
}

// Bound: Q = 0 at every vertex gives the defined texel coordinate 0 (within the probe resolution)
// at every pixel, and Q = 0 at one vertex renders identically for 1 and 3 threads.
TEST(Texture, QZero_DefinedResult) {
  SimHarness h({.width = 64, .height = 64});
  bind_probe(h);
  const auto zero = quad(0, 0, 32, 32, {0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0});
  h.draw(zero);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const auto c = h.color(x, y);
      ASSERT_LE(std::fabs(read_probe_axis(c.r, c.g, 0.0, kW).position), kProbeResolution + 1e-9) << x << "," << y;
      ASSERT_LE(std::fabs(read_probe_axis(c.b, c.a, 0.0, kH).position), kProbeResolution + 1e-9) << x << "," << y;
    }
  std::vector<std::uint8_t> first;
  for (unsigned threads : {1u, 3u}) {
    SimHarness g({.width = 64, .height = 64, .threads = threads});
    bind_probe(g);
    g.draw(quad(0, 0, 64, 64, {0, 0xFFFFFFFF, 0x12345678, 0xFFFFFFFF}, {0, 0.5, 0.25, 3.0}, {0, 0.75, 0.5, 1.0}));
    if (first.empty()) first = g.color_bytes();
    else EXPECT_TRUE(g.color_bytes() == first);
  }
  EXPECT_EQ(h.device_errors(), 0);
}

// Bound: with all three Q equal the device is exactly affine: halving Q and S (an exponent change
// only) gives identical pixels, and the error is within the reciprocal bound.
TEST(Texture, AffineEquivalenceEqualW_ExponentChangeIdentical) {
  std::vector<std::uint8_t> first;
  for (std::uint32_t q : {0x80000000u, 0x40000000u, 0x00800000u}) {
    SimHarness h({.width = 64, .height = 64});
    bind_probe(h);
    const auto tris = quad(0, 0, 64, 64, {q, q, q, q}, {0.125, 1.75, 3.5, -0.5}, {0.25, 0.5, 2.0, 1.0});
    h.draw(tris);
    if (first.empty()) {
      first = h.color_bytes();
      const auto e = measure(h, tris);
      EXPECT_LE(e.worst_excess, 0.0) << "worst texel error " << e.worst;
    } else {
      EXPECT_TRUE(h.color_bytes() == first) << std::hex << q;
    }
  }
}

// Bound: within the reciprocal bound at both ends of every one of the 1024 table intervals (the
// largest reciprocal error sits at interval ends), with |u| close to 4 texture widths.
TEST(Texture, ReciprocalEveryTableIntervalEnd_WithinBound) {
  SimHarness h({.width = 128, .height = 64});
  bind_probe(h);
  std::vector<DeviceTriangle> tris;
  for (std::uint32_t i = 0; i < 1024; ++i)
    for (int end = 0; end < 2; ++end) {
      const std::uint32_t q = 0x80000000u | (i << 21) | (end ? (1u << 21) - 1 : 0);
      const int cell = int(i) * 2 + end, x = (cell % 64) * 2, y = (cell / 64) * 2;
      for (auto& t : quad(x, y, x + 2, y + 2, {q, q, q, q}, {3.97, 3.99, 3.98, 3.96}, {0.3, 0.31, 0.32, 0.33}))
        tris.push_back(t);
    }
  h.draw(tris);
  const auto e = measure(h, tris);
  EXPECT_EQ(e.pixels, 128 * 64);
  EXPECT_LE(e.worst_excess, 0.0) << "worst texel error " << e.worst;
}

// Index texture for nearest sampling: R, G = column low/high byte, B = row.
std::vector<std::uint8_t> index_texture() {
  std::vector<std::uint8_t> b(std::size_t{kW} * kH * 4);
  for (unsigned j = 0; j < kH; ++j)
    for (unsigned i = 0; i < kW; ++i) {
      std::uint8_t* p = &b[(j * kW + i) * 4];
      p[0] = std::uint8_t(i & 255);
      p[1] = std::uint8_t(i >> 8);
      p[2] = std::uint8_t(j);
      p[3] = 255;
    }
  return b;
}

long long address(long long i, long long size, protocol::Wrap wrap) {
  switch (wrap) {
    case protocol::Wrap::Clamp: return std::clamp(i, 0LL, size - 1);
    case protocol::Wrap::Mirror: {
      const long long k = ((i % (2 * size)) + 2 * size) % (2 * size);
      return k < size ? k : 2 * size - 1 - k;
    }
    default: return ((i % size) + size) % size;
  }
}

// Bound: 0 wrong texels (nearest sampling) across the seams u = k * width for k in {0, 1, -1, 31,
// -32, 100, -127}, including slightly negative u (floor, not truncation), for REPEAT, CLAMP and
// MIRROR; pixels whose reference position is within 1/64 texel of a texel border are not judged.
TEST(Texture, WrapSeamsAndNegativeCoordinates_ZeroWrongTexels) {
  for (auto wrap : {protocol::Wrap::Repeat, protocol::Wrap::Clamp, protocol::Wrap::Mirror}) {
    SimHarness h({.width = 64, .height = 64});
    h.texture(index_texture(), {.width = kW, .height = kH, .wrap_s = wrap, .bilinear = false});
    h.state(textured_decal());
    int judged = 0;
    for (double k : {0.0, 1.0, -1.0, 31.0, -32.0, 100.0, -127.0}) {
      h.clear();
      // 16 texels across 64 px around the seam; q varies so the path is perspective.
      const double du = 8.0 / kW;
      const auto tris = quad(0, 0, 64, 64, {0xFFFFFFFF, 0xC0000000, 0xFFFFFFFF, 0xC0000000},
                             {k - du, k + du, k + du, k - du}, {0.1, 0.1, 0.9, 0.9});
      h.draw(tris);
      for (const auto& t : tris)
        for (const auto& s : rasterize(to_fixed(t), h.full_rect())) {
          const double pos = s.u() * kW;
          if (std::fabs(pos - std::round(pos)) < 1.0 / 64) continue;
          const long long want = address(static_cast<long long>(std::floor(pos)), kW, wrap);
          const auto c = h.color(s.x, s.y);
          ASSERT_EQ(c.r + 256 * c.g, want) << "wrap " << int(wrap) << " k " << k << " at " << s.x << "," << s.y;
          ++judged;
        }
    }
    EXPECT_GT(judged, 20000);
  }
}

}  // namespace
}  // namespace gpubridge::accuracy
