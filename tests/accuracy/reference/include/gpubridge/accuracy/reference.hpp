#pragma once
// The double-precision reference rasteriser of the accuracy suite and of `gpubridge bench accuracy`.
//
// It follows the conventions of docs/protocol.md (sections 1, 8, 9, 10) but is written independently
// of the simulator's fixed-point path and kept obvious on purpose:
//   - coverage: edge functions evaluated directly at every pixel centre in double. The snapped 1/16
//     coordinates are small integers, so every product and sum is exact in double (< 2^53) and the
//     top-left rule is a plain comparison with zero;
//   - attributes: barycentric weights b_i / D as doubles, value = sum a_i * b_i / D, not rounded;
//   - texture coordinates: u = s / q from the exact interpolants, in double.
// It also computes "ideal" values from the host's float inputs (before snapping and quantisation),
// which is what the total error of the host conversion + device arithmetic is measured against.
#include <array>
#include <cstdint>
#include <vector>

namespace gpubridge::accuracy {

// One vertex exactly as the registers carry it (VERTEX, COLOR, TEXCOORD).
struct FixedVertex {
  std::int32_t x = 0, y = 0;  // s12.4 in 1/16 pixel units
  std::uint32_t z = 0;        // 24-bit depth
  std::array<std::uint8_t, 4> rgba{255, 255, 255, 255};
  std::uint32_t q = 0xFFFFFFFFu;  // u0.32
  std::int32_t s = 0, t = 0;      // s8.24
};
using FixedTriangle = std::array<FixedVertex, 3>;

// The pixels a draw may touch: scissor already intersected with the framebuffer (section 8.5).
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) x [y0, y1)
};

// One covered pixel with its exact (unrounded) attribute values.
struct RefSample {
  int x = 0, y = 0;
  double z = 0;                   // 24-bit units
  std::array<double, 4> rgba{};   // 8-bit units
  double s = 0, t = 0, q = 0;     // register units (s8.24, s8.24, u0.32)
  // u = S / Q in texture widths, with S = s / 2^24 and Q = q / 2^32 (0 when q is 0: the device
  // defines q = 0 as texel coordinate 0).
  double u() const { return q != 0 ? 256.0 * s / q : 0.0; }
  double v() const { return q != 0 ? 256.0 * t / q : 0.0; }
};

// Twice the signed area in 1/256 pixel^2 units (the D of section 8.1, before the exchange).
double signed_area(const FixedTriangle& tri);

// True when pixel (px, py) is covered by the triangle (top-left rule, either winding).
bool covers(const FixedTriangle& tri, int px, int py);

// Every covered pixel inside `clip`, rows top to bottom, left to right.
std::vector<RefSample> rasterize(const FixedTriangle& tri, const PixelRect& clip);

// Exact attribute values at pixel (px, py) (valid for covered pixels; extrapolates outside).
RefSample sample_at(const FixedTriangle& tri, int px, int py);

// A vertex as the host supplies it: float pixel position (y down), depth in [0, 1], w > 0,
// colour in [0, 1], texture coordinates in texture widths/heights.
struct HostVertex {
  double x = 0, y = 0, z = 0, w = 1;
  std::array<double, 4> rgba{1, 1, 1, 1};
  double u = 0, v = 0;
};
using HostTriangle = std::array<HostVertex, 3>;

// Ideal values at the centre of pixel (px, py) from the unsnapped host triangle: screen-linear z and
// colour, perspective-correct u and v. Units: z in 24-bit LSB (z * 0xFFFFFF), colour in 8-bit LSB
// (c * 255), u/v in texture widths/heights. Returns false for a degenerate (zero-area) triangle.
struct IdealSample {
  double z = 0;
  std::array<double, 4> rgba{};
  double u = 0, v = 0;
};
bool ideal_at(const HostTriangle& tri, int px, int py, IdealSample& out);

}  // namespace gpubridge::accuracy
