#pragma once
// Clipping of triangles in homogeneous coordinates.
//
// The pipeline works in window-homogeneous space (X, Y, Z, W) = (sx·w, sy·w, z·w, w) where
// (sx, sy) are pixel coordinates and z in [0, 1] the depth (see viewport_matrix). Attributes
// (colour, u, v) are carried unchanged; interpolating them linearly in homogeneous space is
// perspective-correct. A plane is the set dot(plane, P) = 0; the kept side is dot >= 0.
//
// Near clipping follows the Foenix approach: each triangle is clipped right before
// rasterisation, producing 0, 1 or 2 triangles. Intersection points are always computed from the
// kept vertex towards the dropped one, so two triangles sharing an edge get bit-identical new
// vertices (no cracks along clipped shared edges).
#include <array>
#include <cstddef>

#include "gpubridge/geometry/math.hpp"

namespace gpubridge::geometry {

struct Vertex {
  Vec4 pos;                  // window-homogeneous (or clip space: both are linear images)
  Vec4 color{1, 1, 1, 1};    // r, g, b, a in [0, 1]
  Vec2 uv;                   // texture coordinates in texture widths / heights
  friend bool operator==(const Vertex&, const Vertex&) = default;
};
using Triangle = std::array<Vertex, 3>;

// Point on segment a→b at parameter t, all attributes interpolated.
Vertex interpolate(const Vertex& a, const Vertex& b, double t);

// The near plane: Z >= 0 (depth 0 in front of the eye, W > 0 there for perspective()).
inline constexpr Vec4 kNearPlane{0, 0, 1, 0};
// The far plane: Z <= W.
inline constexpr Vec4 kFarPlane{0, 0, -1, 1};

// Result of clipping one triangle against one plane: 0, 1 or 2 triangles, same winding as the
// input. Triangles that only touch the plane (no vertex strictly on the kept side) vanish.
struct ClipResult {
  std::array<Triangle, 2> triangles{};
  std::size_t count = 0;
};
ClipResult clip_triangle(const Triangle& tri, Vec4 plane);
inline ClipResult clip_near(const Triangle& tri) { return clip_triangle(tri, kNearPlane); }

// A convex polygon with a fixed capacity (a triangle clipped by up to 8 planes).
struct Polygon {
  static constexpr std::size_t kCapacity = 11;
  std::array<Vertex, kCapacity> v{};
  std::size_t count = 0;
};
Polygon polygon_from(const Triangle& tri);
// Sutherland–Hodgman against one plane, keeping dot(plane, P) + offset >= 0 (offset != 0 gives
// affine half-spaces such as W >= min_w). Polygons with fewer than 3 vertices become empty.
Polygon clip_polygon(const Polygon& in, Vec4 plane, double offset = 0.0);

// The same clipper without copying whole polygons (what the pipeline uses: a Polygon is
// 11 × 80 bytes, and zero-initialising, returning and assigning one per plane was the largest
// single cost of process_triangle in perf profiles of the near-clip benchmark).
struct PolygonView {
  const Vertex* v = nullptr;
  std::size_t count = 0;
};
// Room for one clipped polygon, deliberately left uninitialised: the clipper writes every vertex
// before anything reads it.
struct ClipBuffer {
  union {
    Vertex v[Polygon::kCapacity];
  };
  ClipBuffer() {}  // NOLINT: no initialisation on purpose
};
// Same rules and bit-identical vertices as clip_polygon. Returns `in` itself when no vertex lies
// outside the plane; otherwise the clipped polygon, written into `out` (which must not overlap
// `in`), count 0 when no area is left.
PolygonView clip_polygon_view(PolygonView in, Vec4 plane, double offset, ClipBuffer& out);

// The 2D guard band, in pixels: every emitted vertex lies inside [min, max] on both axes.
// The default keeps a 1-pixel margin inside the 12.4 register range [-2048, 2047.9375] so that
// floating-point error after the divide can never push a snapped vertex out of range.
struct GuardBand {
  double min = -2047.0;
  double max = 2047.0;
};
// The four guard-band lines written as window-homogeneous planes (X >= min·W, ...).
std::array<Vec4, 4> guard_band_planes(const GuardBand& gb);
// True when every vertex (W > 0) already lies inside the guard band (the common, cheap case).
bool inside_guard_band(const Triangle& tri, const GuardBand& gb);

}  // namespace gpubridge::geometry
