#include "gpubridge/geometry/convert.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace gpubridge::geometry {
namespace {

Error not_finite(std::string_view what, double v) {
  return make_error(fmt::format("{}: {} is not allowed (values must be finite numbers)", what,
                                std::isnan(v) ? "NaN" : (v > 0 ? "+Inf" : "-Inf")));
}

}  // namespace

Result<std::int16_t> snap_12_4(double x, std::string_view what) {
  if (!std::isfinite(x)) return not_finite(what, x);
  // floor(16x + 0.5) evaluated exactly: 16x is exact (power of two), and so is its fractional
  // part, whereas adding 0.5 first could round values just below a tie up to it.
  const double sixteen_x = 16.0 * x;
  const double whole = std::floor(sixteen_x);
  const double s = whole + (sixteen_x - whole >= 0.5 ? 1.0 : 0.0);
  if (s < -32768.0 || s > 32767.0)
    return make_error(fmt::format("{}: {} px is outside the 12.4 register range [-2048, 2047.9375]", what, x));
  return static_cast<std::int16_t>(s);
}

Result<std::uint32_t> depth_to_z24(double z) {
  if (!std::isfinite(z)) return not_finite("z", z);
  if (z < -1e-9) return make_error(fmt::format("z: {} is below 0 (depth must be in [0, 1])", z));
  // z·16777215 is not exact in double; the product's error (≤ 2^-29) only matters within that
  // distance of a tie, where either neighbour is within the documented ±0.5 LSB bound.
  const double s = std::floor(std::clamp(z, 0.0, 1.0) * 16777215.0 + 0.5);
  return static_cast<std::uint32_t>(std::min(s, 16777215.0));
}

Result<std::uint8_t> unit_to_u8(double c, std::string_view what) {
  if (!std::isfinite(c)) return not_finite(what, c);
  return static_cast<std::uint8_t>(std::clamp(std::round(c * 255.0), 0.0, 255.0));
}

Result<std::uint32_t> color_to_rgba8(Vec4 c) {
  const double ch[4] = {c.x, c.y, c.z, c.w};
  static constexpr std::string_view names[4] = {"r", "g", "b", "a"};
  std::uint32_t out = 0;
  for (int i = 0; i < 4; ++i) {
    auto v = unit_to_u8(ch[i], names[i]);
    if (!v) return v.error();
    out = (out << 8) | *v;
  }
  return out;
}

double texture_offset(double min_coord, protocol::Wrap wrap) {
  switch (wrap) {
    case protocol::Wrap::Repeat: return std::floor(min_coord);
    case protocol::Wrap::Mirror: return 2.0 * std::floor(min_coord / 2.0);
    default: return 0.0;
  }
}

namespace {

// Exact floor and round-half-away-from-zero for finite doubles, inline: the libm calls (the
// baseline x86-64 target has no rounding instruction) cost more than the rest of a conversion.
// Below 2^52 the truncation fits an int64 and x − trunc(x) is exact; from 2^52 up every double
// is an integer. Only the sign of a zero result can differ from std::floor / std::round, and
// every use below converts the result to an integer, where −0 and +0 are the same.
constexpr double kTwoPow52 = 4503599627370496.0;

// The corrections are written as added 0/1 terms so that they compile to compare-and-mask
// instructions: the fractions of S, T and Q are random, and a branch on them mispredicts half the
// time (slower than the libm call it replaces).
inline double floor_exact(double x) {
  if (!(std::fabs(x) < kTwoPow52)) return x;
  const double t = static_cast<double>(static_cast<std::int64_t>(x));
  return t - (t > x ? 1.0 : 0.0);
}

inline double round_exact(double x) {
  if (!(std::fabs(x) < kTwoPow52)) return x;
  const double t = static_cast<double>(static_cast<std::int64_t>(x));
  const double frac = x - t;
  return (t + (frac >= 0.5 ? 1.0 : 0.0)) - (frac <= -0.5 ? 1.0 : 0.0);
}

// The conversion of convert_triangle_checked for input that needs no error message: the same
// expressions, without Result values and error names per value. Returns false on anything that
// would be an error; convert_triangle then runs the checked version, which names the problem.
bool convert_triangle_fast(const std::array<ScreenVertex, 3>& tri, const TexAddressing& tex, DeviceTriangle& out) {
  double qmax = 0;
  std::array<double, 3> q{};
  for (int i = 0; i < 3; ++i) {
    const auto& v = tri[i];
    if (!std::isfinite(v.w) || !std::isfinite(v.uv.x) || !std::isfinite(v.uv.y) || !(v.w > 0)) return false;
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) return false;
    double snapped[2];
    for (int k = 0; k < 2; ++k) {
      const double sixteen_x = 16.0 * (k == 0 ? v.x : v.y);  // as snap_12_4
      const double whole = floor_exact(sixteen_x);
      snapped[k] = whole + (sixteen_x - whole >= 0.5 ? 1.0 : 0.0);
      if (snapped[k] < -32768.0 || snapped[k] > 32767.0) return false;
    }
    if (v.z < -1e-9) return false;  // as depth_to_z24
    const double zs = floor_exact(std::clamp(v.z, 0.0, 1.0) * 16777215.0 + 0.5);
    const double ch[4] = {v.color.x, v.color.y, v.color.z, v.color.w};
    std::uint32_t rgba = 0;
    for (double c : ch) {  // as unit_to_u8 / color_to_rgba8
      if (!std::isfinite(c)) return false;
      rgba = (rgba << 8) | static_cast<std::uint8_t>(std::clamp(round_exact(c * 255.0), 0.0, 255.0));
    }
    out[i].x = static_cast<std::int16_t>(snapped[0]);
    out[i].y = static_cast<std::int16_t>(snapped[1]);
    out[i].z = static_cast<std::uint32_t>(std::min(zs, 16777215.0));
    out[i].rgba = rgba;
    q[i] = 1.0 / v.w;
    if (!std::isfinite(q[i])) return false;
    qmax = std::max(qmax, q[i]);
  }
  const double u_off = texture_offset(std::min({tri[0].uv.x, tri[1].uv.x, tri[2].uv.x}), tex.wrap_s);
  const double v_off = texture_offset(std::min({tri[0].uv.y, tri[1].uv.y, tri[2].uv.y}), tex.wrap_t);
  for (int i = 0; i < 3; ++i) {
    const double qn = round_exact(q[i] / qmax * 4294967295.0);
    out[i].q = static_cast<std::uint32_t>(qn);
    const double du = tri[i].uv.x - u_off, dv = tri[i].uv.y - v_off;
    if (!(std::fabs(du) < kMaxTexOffset) || !(std::fabs(dv) < kMaxTexOffset)) return false;
    out[i].s = static_cast<std::int32_t>(std::clamp(round_exact(du * qn / 256.0), -2147483648.0, 2147483647.0));
    out[i].t = static_cast<std::int32_t>(std::clamp(round_exact(dv * qn / 256.0), -2147483648.0, 2147483647.0));
  }
  return true;
}

// Every check with its own message; also the reference the fast path must match bit for bit.
Result<DeviceTriangle> convert_triangle_checked(const std::array<ScreenVertex, 3>& tri, const TexAddressing& tex) {
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

}  // namespace

Result<DeviceTriangle> convert_triangle(const std::array<ScreenVertex, 3>& tri, const TexAddressing& tex) {
  DeviceTriangle out;
  if (convert_triangle_fast(tri, tex, out)) return out;
  return convert_triangle_checked(tri, tex);
}

}  // namespace gpubridge::geometry
