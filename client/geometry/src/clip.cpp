#include "gpubridge/geometry/clip.hpp"

#include <algorithm>

namespace gpubridge::geometry {

Vertex interpolate(const Vertex& a, const Vertex& b, double t) {
  return Vertex{lerp(a.pos, b.pos, t), lerp(a.color, b.color, t), lerp(a.uv, b.uv, t)};
}

namespace {

// Intersection of edge (in, out) with the plane, computed from the kept vertex so the result
// does not depend on the order in which a triangle lists the edge.
Vertex intersect(const Vertex& in, double d_in, const Vertex& out, double d_out) {
  const double t = d_in / (d_in - d_out);  // d_in > 0 > d_out: t in (0, 1), denominator > 0
  Vertex v = interpolate(in, out, t);
  return v;
}

}  // namespace

Polygon polygon_from(const Triangle& tri) {
  Polygon p;
  for (const auto& v : tri) p.v[p.count++] = v;
  return p;
}

PolygonView clip_polygon_view(PolygonView in, Vec4 plane, double offset, ClipBuffer& out) {
  if (in.count < 3) return {out.v, 0};
  std::array<double, Polygon::kCapacity> d;
  const std::size_t n = std::min(in.count, Polygon::kCapacity);
  bool any_strictly_inside = false, any_outside = false;
  for (std::size_t i = 0; i < n; ++i) {
    d[i] = dot(plane, in.v[i].pos) + offset;
    any_strictly_inside |= d[i] > 0;
    any_outside |= d[i] < 0;
  }
  if (!any_strictly_inside && any_outside) return {out.v, 0};  // touches the plane at most: no area left
  if (!any_outside) return in;                                   // fully kept (NaN distances count as kept)
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = i + 1 == n ? 0 : i + 1;
    const Vertex& a = in.v[i];
    const Vertex& b = in.v[j];
    if (d[i] >= 0 && count < Polygon::kCapacity) out.v[count++] = a;
    // A new vertex only where the edge strictly crosses the plane; on-plane vertices are kept.
    if ((d[i] > 0 && d[j] < 0) && count < Polygon::kCapacity) out.v[count++] = intersect(a, d[i], b, d[j]);
    if ((d[i] < 0 && d[j] > 0) && count < Polygon::kCapacity) out.v[count++] = intersect(b, d[j], a, d[i]);
  }
  return {out.v, count < 3 ? 0 : count};
}

Polygon clip_polygon(const Polygon& in, Vec4 plane, double offset) {
  ClipBuffer buffer;
  const PolygonView r = clip_polygon_view({in.v.data(), in.count}, plane, offset, buffer);
  if (r.v == in.v.data()) return in;
  Polygon out;
  std::copy(r.v, r.v + r.count, out.v.begin());
  out.count = r.count;
  return out;
}

ClipResult clip_triangle(const Triangle& tri, Vec4 plane) {
  const Polygon p = clip_polygon(polygon_from(tri), plane);
  ClipResult r;
  // A triangle clipped by one plane has at most 4 vertices: fan it into at most 2 triangles.
  for (std::size_t i = 1; i + 1 < p.count && r.count < 2; ++i) r.triangles[r.count++] = {p.v[0], p.v[i], p.v[i + 1]};
  return r;
}

std::array<Vec4, 4> guard_band_planes(const GuardBand& gb) {
  return {Vec4{1, 0, 0, -gb.min},    // X - min·W >= 0
          Vec4{-1, 0, 0, gb.max},    // max·W - X >= 0
          Vec4{0, 1, 0, -gb.min},    // Y - min·W >= 0
          Vec4{0, -1, 0, gb.max}};   // max·W - Y >= 0
}

bool inside_guard_band(const Triangle& tri, const GuardBand& gb) {
  for (const auto& v : tri) {
    if (!(v.pos.w > 0)) return false;
    const double x = v.pos.x / v.pos.w, y = v.pos.y / v.pos.w;
    if (!(x >= gb.min && x <= gb.max && y >= gb.min && y <= gb.max)) return false;
  }
  return true;
}

}  // namespace gpubridge::geometry
