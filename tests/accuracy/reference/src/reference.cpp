// Double-precision reference rasteriser (see reference.hpp for what it is and why it is exact).
#include "gpubridge/accuracy/reference.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace gpubridge::accuracy {
namespace {

// The triangle in counter-clockwise order of a y-down screen (positive area), as section 8.1 does
// it: when the area is negative the second and third vertices are exchanged.
struct Oriented {
  std::array<FixedVertex, 3> v;
  double area = 0;  // D > 0, or 0 for a degenerate triangle
};

Oriented orient(const FixedTriangle& tri) {
  Oriented o{tri, signed_area(tri)};
  if (o.area < 0) {
    std::swap(o.v[1], o.v[2]);
    o.area = -o.area;
  }
  return o;
}

// Edge function of the directed edge a -> b at point (x, y), all in 1/16 pixel units. Every
// operand is an integer below 2^17 and every product below 2^35: exact in double.
double edge(const FixedVertex& a, const FixedVertex& b, double x, double y) {
  return double(b.x - a.x) * (y - a.y) - double(b.y - a.y) * (x - a.x);
}

// Top edge: exactly horizontal and running right (the interior is below it on a y-down screen);
// left edge: running up. A sample exactly on such an edge belongs to the triangle.
bool owns_samples_on(const FixedVertex& a, const FixedVertex& b) {
  const bool top = a.y == b.y && b.x > a.x;
  const bool left = b.y < a.y;
  return top || left;
}

bool inside(const Oriented& o, double sx, double sy) {
  for (int i = 0; i < 3; ++i) {
    const FixedVertex& a = o.v[i];
    const FixedVertex& b = o.v[(i + 1) % 3];
    const double e = edge(a, b, sx, sy);
    if (e < 0 || (e == 0 && !owns_samples_on(a, b))) return false;
  }
  return true;
}

double sample_x(int px) { return 16.0 * px + 8.0; }

RefSample evaluate(const Oriented& o, int px, int py) {
  const double sx = sample_x(px), sy = sample_x(py);
  // Barycentric weights of v1 and v2; the attribute is a0 + (a1 - a0) w1 + (a2 - a0) w2, which is
  // exact for constant attributes and within a few ulp otherwise.
  const double w1 = edge(o.v[2], o.v[0], sx, sy) / o.area;
  const double w2 = edge(o.v[0], o.v[1], sx, sy) / o.area;
  auto lerp = [&](double a0, double a1, double a2) { return a0 + (a1 - a0) * w1 + (a2 - a0) * w2; };
  RefSample s;
  s.x = px;
  s.y = py;
  s.z = lerp(o.v[0].z, o.v[1].z, o.v[2].z);
  for (int c = 0; c < 4; ++c) s.rgba[c] = lerp(o.v[0].rgba[c], o.v[1].rgba[c], o.v[2].rgba[c]);
  s.s = lerp(o.v[0].s, o.v[1].s, o.v[2].s);
  s.t = lerp(o.v[0].t, o.v[1].t, o.v[2].t);
  s.q = lerp(o.v[0].q, o.v[1].q, o.v[2].q);
  return s;
}

}  // namespace

double signed_area(const FixedTriangle& t) {
  return double(t[1].x - t[0].x) * double(t[2].y - t[0].y) - double(t[2].x - t[0].x) * double(t[1].y - t[0].y);
}

bool covers(const FixedTriangle& tri, int px, int py) {
  const Oriented o = orient(tri);
  return o.area != 0 && inside(o, sample_x(px), sample_x(py));
}

RefSample sample_at(const FixedTriangle& tri, int px, int py) {
  const Oriented o = orient(tri);
  if (o.area == 0) return RefSample{px, py};
  return evaluate(o, px, py);
}

std::vector<RefSample> rasterize(const FixedTriangle& tri, const PixelRect& clip) {
  std::vector<RefSample> out;
  const Oriented o = orient(tri);
  if (o.area == 0) return out;
  // A generous pixel box around the vertices; the exact test decides.
  int lo_x = tri[0].x, hi_x = tri[0].x, lo_y = tri[0].y, hi_y = tri[0].y;
  for (const auto& v : tri) {
    lo_x = std::min(lo_x, v.x);
    hi_x = std::max(hi_x, v.x);
    lo_y = std::min(lo_y, v.y);
    hi_y = std::max(hi_y, v.y);
  }
  const int x0 = std::max(clip.x0, lo_x / 16 - 1), x1 = std::min(clip.x1, hi_x / 16 + 2);
  const int y0 = std::max(clip.y0, lo_y / 16 - 1), y1 = std::min(clip.y1, hi_y / 16 + 2);
  for (int py = y0; py < y1; ++py)
    for (int px = x0; px < x1; ++px)
      if (inside(o, sample_x(px), sample_x(py))) out.push_back(evaluate(o, px, py));
  return out;
}

bool ideal_at(const HostTriangle& t, int px, int py, IdealSample& out) {
  const double cx = px + 0.5, cy = py + 0.5;
  const double area = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y);
  if (area == 0 || !std::isfinite(area)) return false;
  // Barycentric weights from the float positions (sub-areas opposite each vertex).
  const double l1 = ((cx - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (cy - t[0].y)) / area;
  const double l2 = ((t[1].x - t[0].x) * (cy - t[0].y) - (cx - t[0].x) * (t[1].y - t[0].y)) / area;
  const double l0 = 1.0 - l1 - l2;
  const double lam[3] = {l0, l1, l2};
  out = IdealSample{};
  double inv_w = 0, u_w = 0, v_w = 0;
  for (int i = 0; i < 3; ++i) {
    out.z += lam[i] * t[i].z * 16777215.0;
    for (int c = 0; c < 4; ++c) out.rgba[c] += lam[i] * t[i].rgba[c] * 255.0;
    inv_w += lam[i] / t[i].w;
    u_w += lam[i] * t[i].u / t[i].w;
    v_w += lam[i] * t[i].v / t[i].w;
  }
  out.u = inv_w != 0 ? u_w / inv_w : 0;
  out.v = inv_w != 0 ? v_w / inv_w : 0;
  return true;
}

}  // namespace gpubridge::accuracy
