#pragma once
// Conversion of screen-space values to the spigpu register formats (docs/protocol.md,
// "Host conventions"). Every function rejects NaN and ±Inf with an Error naming the value.
//
// Error bounds (exact integer rounding of double inputs; double error is negligible):
//   X, Y  : |snapped − x| ≤ 1/32 px (round half up: X = floor(16·x + 0.5)).
//   Z     : |Z/16777215 − z| ≤ 0.5/16777215 for z in [0, 1].
//   colour: |C/255 − c| ≤ 0.5/255.
//   Q     : per triangle the largest q = 1/w maps to 0xFFFFFFFF; relative error of the others
//           ≤ 2^-33 / (Q/2^32) (i.e. ≤ 2^-32 relative at full scale, worse as Q → 0).
//   S, T  : |S/Q − (u − u_off)| ≤ 2^-24 · 2^32/Q + |u − u_off|·(Q rounding) — below 2^-23
//           texture widths when Q ≥ 2^31; see docs for the derivation.
#include <array>
#include <cstdint>
#include <string_view>

#include "gpubridge/common/result.hpp"
#include "gpubridge/geometry/math.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::geometry {

inline constexpr double kMinCoord = -2048.0;      // 12.4 range in pixels
inline constexpr double kMaxCoord = 2047.9375;
inline constexpr double kMaxTexOffset = 128.0;    // |u − u_off| must stay below this (signed 8.24)

// X = floor(16·x + 0.5) as a signed 12.4 value; `what` names the value in errors ("x").
Result<std::int16_t> snap_12_4(double x, std::string_view what = "coordinate");
// Z = min(0xFFFFFF, floor(z·16777215 + 0.5)); z < 0 is an error beyond −1e-9 and clamps to 0 above
// it (tiny negative values come from clipping round-off), z > 1 clamps to 0xFFFFFF.
Result<std::uint32_t> depth_to_z24(double z);
// round(c·255) clamped to 0..255.
Result<std::uint8_t> unit_to_u8(double c, std::string_view what = "colour");
// 0xRRGGBBAA from r, g, b, a in [0, 1].
Result<std::uint32_t> color_to_rgba8(Vec4 c);

// The texture-coordinate offset subtracted per triangle before forming S and T. Repeat and
// mirror patterns are invariant under it, so the sampled texels are unchanged.
double texture_offset(double min_coord, protocol::Wrap wrap);

// A vertex after perspective divide: pixel position, depth in [0, 1], w > 0 (the divisor).
struct ScreenVertex {
  double x = 0, y = 0, z = 0, w = 1;
  Vec4 color{1, 1, 1, 1};
  Vec2 uv;
};

// One vertex in register form.
struct DeviceVertex {
  std::int16_t x = 0, y = 0;  // 12.4
  std::uint32_t z = 0;        // 24 bits
  std::uint32_t rgba = 0;     // 0xRRGGBBAA
  std::uint32_t q = 0;        // unsigned 0.32
  std::int32_t s = 0, t = 0;  // signed 8.24
  friend bool operator==(const DeviceVertex&, const DeviceVertex&) = default;
};
using DeviceTriangle = std::array<DeviceVertex, 3>;

struct TexAddressing {
  protocol::Wrap wrap_s = protocol::Wrap::Repeat;
  protocol::Wrap wrap_t = protocol::Wrap::Repeat;
};

// Converts one triangle: snapping, depth, colours, and the per-triangle S/T/Q normalisation
//   q_i = 1/w_i, Q_i = round(q_i / max q · (2^32 − 1)), S_i = round((u_i − u_off) · Q_i / 2^8).
// Errors: NaN/Inf anywhere, w <= 0, a coordinate outside the 12.4 range, |u − u_off| >= 128.
Result<DeviceTriangle> convert_triangle(const std::array<ScreenVertex, 3>& tri, const TexAddressing& tex);

// Register words of a converted vertex.
constexpr std::uint64_t color_word(const DeviceVertex& v) { return (std::uint64_t{v.q} << 32) | v.rgba; }
constexpr std::uint64_t texcoord_word(const DeviceVertex& v) {
  return (std::uint64_t{static_cast<std::uint32_t>(v.s)} << 32) | static_cast<std::uint32_t>(v.t);
}
constexpr std::uint64_t vertex_word(const DeviceVertex& v) {
  return (std::uint64_t{v.z & 0xFFFFFFu} << 32) | (std::uint64_t{static_cast<std::uint16_t>(v.y)} << 16) |
         static_cast<std::uint16_t>(v.x);
}

}  // namespace gpubridge::geometry
