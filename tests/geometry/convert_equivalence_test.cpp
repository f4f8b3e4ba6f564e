// convert_triangle's inline fast path against the conversion it replaced, kept here verbatim as
// the reference (commit 938ddef): every register value must agree bit for bit, and input the fast
// path declines must give the reference's error message word for word. Inputs cover rounding
// ties (x.5/16 px, k.5/255 colours), the 12.4 and depth limits, tiny and huge W, negative and
// large texture coordinates, and NaN/Inf anywhere.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <fmt/format.h>

#include "gpubridge/geometry/convert.hpp"

namespace gpubridge::geometry {
namespace {

// --- reference: the conversion before the fast path ---
Error not_finite(std::string_view what, double v) {
  return make_error(fmt::format("{}: {} is not allowed (values must be finite numbers)", what,
                                std::isnan(v) ? "NaN" : (v > 0 ? "+Inf" : "-Inf")));
}

Result<DeviceTriangle> ref_convert_triangle(const std::array<ScreenVertex, 3>& tri, const TexAddressing& tex) {
  DeviceTriangle out;
  // Names are constants: formatting them per vertex would dominate the cost of a conversion.
  static constexpr std::string_view vnames[3] = {"vertex 0", "vertex 1", "vertex 2"};
  static constexpr std::string_view xnames[3] = {"vertex 0: x", "vertex 1: x", "vertex 2: x"};
  static constexpr std::string_view ynames[3] = {"vertex 0: y", "vertex 1: y", "vertex 2: y"};
  double qmax = 0;
  std::array<double, 3> q{};
  for (int i = 0; i < 3; ++i) {
    const auto& v = tri[i];
    for (double a : {v.w, v.uv.x, v.uv.y})
      if (!std::isfinite(a)) return not_finite(fmt::format("{}: w/u/v", vnames[i]), a);
    if (!(v.w > 0)) return make_error(fmt::format("{}: w = {} must be > 0 (clip against the near plane first)", vnames[i], v.w));
    auto x = snap_12_4(v.x, xnames[i]);
    if (!x) return x.error();
    auto y = snap_12_4(v.y, ynames[i]);
    if (!y) return y.error();
    auto z = depth_to_z24(v.z);
    if (!z) return make_error(fmt::format("{}: {}", vnames[i], z.error().message));
    auto c = color_to_rgba8(v.color);
    if (!c) return make_error(fmt::format("{}: {}", vnames[i], c.error().message));
    out[i].x = *x;
    out[i].y = *y;
    out[i].z = *z;
    out[i].rgba = *c;
    q[i] = 1.0 / v.w;
    if (!std::isfinite(q[i])) return make_error(fmt::format("{}: w = {} is too small (1/w overflows)", vnames[i], v.w));
    qmax = std::max(qmax, q[i]);
  }
  const double u_off = texture_offset(std::min({tri[0].uv.x, tri[1].uv.x, tri[2].uv.x}), tex.wrap_s);
  const double v_off = texture_offset(std::min({tri[0].uv.y, tri[1].uv.y, tri[2].uv.y}), tex.wrap_t);
  for (int i = 0; i < 3; ++i) {
    const double qn = std::round(q[i] / qmax * 4294967295.0);  // q[i] <= qmax: at most 2^32 - 1
    out[i].q = static_cast<std::uint32_t>(qn);
    const double du = tri[i].uv.x - u_off, dv = tri[i].uv.y - v_off;
    if (!(std::fabs(du) < kMaxTexOffset) || !(std::fabs(dv) < kMaxTexOffset))
      return make_error(fmt::format(
          "{}: texture coordinate ({}, {}) is {} or more texture sizes from the triangle's offset ({}, {}); "
          "S/T (signed 8.24) cannot hold it — subdivide the triangle or use REPEAT/MIRROR wrapping",
          vnames[i], tri[i].uv.x, tri[i].uv.y, kMaxTexOffset, u_off, v_off));
    // |du| < 128 and qn < 2^32: |du · qn / 256| < 2^31, so the rounded value fits in int32.
    out[i].s = static_cast<std::int32_t>(std::clamp(std::round(du * qn / 256.0), -2147483648.0, 2147483647.0));
    out[i].t = static_cast<std::int32_t>(std::clamp(std::round(dv * qn / 256.0), -2147483648.0, 2147483647.0));
  }
  return out;
}

// --- end of reference ---

void expect_same(const std::array<ScreenVertex, 3>& tri, const TexAddressing& tex, std::size_t& ok, std::size_t& errors) {
  const auto ref = ref_convert_triangle(tri, tex);
  const auto got = convert_triangle(tri, tex);
  ASSERT_EQ(static_cast<bool>(got), static_cast<bool>(ref)) << (ref ? got.error().message : ref.error().message);
  if (ref) {
    ASSERT_EQ(*got, *ref);
    ++ok;
  } else {
    ASSERT_EQ(got.error().message, ref.error().message);
    ++errors;
  }
}

TEST(ConvertEquivalence, RandomTrianglesMatchTheOriginalConversionBitForBit) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0, 1), px(-2100, 2100), uv(-140, 140), small_uv(-3, 3);
  std::uniform_int_distribution<int> tick(-32800, 32800), c255(-3, 258), pick(0, 15);
  const double kNaN = std::numeric_limits<double>::quiet_NaN(), kInf = std::numeric_limits<double>::infinity();
  auto coordinate = [&]() -> double {
    switch (pick(rng) % 4) {
      case 0: return (tick(rng) + 0.5) / 16.0;  // exactly on a snapping tie
      case 1: return std::nextafter((tick(rng) + 0.5) / 16.0, 0.0);
      case 2: return tick(rng) / 16.0;
      default: return px(rng);
    }
  };
  auto channel = [&]() -> double {
    switch (pick(rng) % 4) {
      case 0: return (c255(rng) + 0.5) / 255.0;  // near a rounding tie (the division is not exact)
      case 1: return c255(rng) / 255.0;
      case 2: return unit(rng) * 1.2 - 0.1;
      default: return unit(rng);
    }
  };
  const TexAddressing modes[] = {{}, {protocol::Wrap::Mirror, protocol::Wrap::Clamp}};
  std::size_t ok = 0, errors = 0;
  for (int n = 0; n < 60000; ++n) {
    std::array<ScreenVertex, 3> tri;
    for (auto& v : tri) {
      v.x = coordinate();
      v.y = coordinate();
      v.z = pick(rng) == 0 ? -2e-9 * unit(rng) : (pick(rng) == 0 ? (std::floor(unit(rng) * 16777215) + 0.5) / 16777215 : unit(rng) * 1.1);
      v.w = pick(rng) == 0 ? std::ldexp(unit(rng), -1000) : std::exp(unit(rng) * 20 - 10);
      v.color = {channel(), channel(), channel(), channel()};
      v.uv = pick(rng) < 2 ? Vec2{uv(rng), uv(rng)} : Vec2{small_uv(rng), small_uv(rng)};
    }
    if (n % 97 == 0) {  // a NaN or Inf somewhere
      double* fields[] = {&tri[1].x, &tri[1].y, &tri[1].z, &tri[1].w, &tri[1].color.y, &tri[1].uv.x};
      *fields[n % 6] = (n % 2) ? kNaN : -kInf;
    }
    expect_same(tri, modes[n % 2], ok, errors);
    if (HasFatalFailure()) return;
  }
  // Both paths were exercised: plenty of conversions and plenty of errors.
  EXPECT_GT(ok, 20000u);
  EXPECT_GT(errors, 5000u);
}

}  // namespace
}  // namespace gpubridge::geometry
