#include "setup.hpp"

#include "color_planes.hpp"

#include <algorithm>
#include <utility>

namespace gpubridge::sim {
namespace {

// Top-left rule (section 8.3): bias 0 for top or left edges, −1 otherwise.
std::int64_t edge_bias(const Vertex& a, const Vertex& b) {
  const bool top = a.y == b.y && b.x > a.x;
  const bool left = b.y < a.y;
  return top || left ? 0 : -1;
}

// Raw edge function a → b at sample point (sx, sy) and its per-pixel steps.
Edge make_edge(const Vertex& a, const Vertex& b, std::int64_t sx, std::int64_t sy) {
  Edge e;
  const std::int64_t dx = std::int64_t{b.x} - a.x, dy = std::int64_t{b.y} - a.y;
  e.e = dx * (sy - a.y) - dy * (sx - a.x);
  e.ex = -16 * dy;
  e.ey = 16 * dx;
  return e;
}

void setup_plane(Plane& p, std::int64_t a0, std::int64_t a1, std::int64_t a2, const Edge& b1, const Edge& b2,
                 std::int64_t D, const Divider& den) {
  const std::int64_t d1 = a1 - a0, d2 = a2 - a0;
  if (d1 == 0 && d2 == 0) {
    p = Plane{};
    p.q = a0;
    return;
  }
  p.constant = false;
  // |b.e| < 2^35 (12.4 coordinates), so colour and Z deltas (< 2^25) keep M inside 64 bits;
  // only S/T/Q need the 128-bit product.
  constexpr std::int64_t kNarrow = std::int64_t{1} << 25;
  const bool narrow = d1 < kNarrow && d1 > -kNarrow && d2 < kNarrow && d2 > -kNarrow;
  const DivMod o = narrow ? den(2 * (d1 * b1.e + d2 * b2.e) + D) : den(2 * (i128{d1} * b1.e + i128{d2} * b2.e) + D);
  p.q = a0 + o.q;
  p.r = o.r;
  const DivMod sx = den(2 * (d1 * b1.ex + d2 * b2.ex));
  const DivMod sy = den(2 * (d1 * b1.ey + d2 * b2.ey));
  p.qx = sx.q;
  p.rx = sx.r;
  p.qy = sy.q;
  p.ry = sy.r;
}

}  // namespace

bool setup_triangle(const Vertex& va, const Vertex& vb, const Vertex& vc, const DrawState& state,
                    unsigned subpixel_bits, bool all_attributes, Triangle& t) {
  // subpixel_bits < 4 truncates the vertex coordinates first.
  const std::int32_t keep = subpixel_bits < 4 ? ~((std::int32_t{1} << (4 - subpixel_bits)) - 1) : ~std::int32_t{0};
  const std::int64_t ax = va.x & keep, ay = va.y & keep;
  std::int64_t D = ((vb.x & keep) - ax) * ((vc.y & keep) - ay) - ((vc.x & keep) - ax) * ((vb.y & keep) - ay);
  if (D == 0) return false;
  // The exchange of section 8.1 as a select, not a branch: the winding of consecutive triangles
  // is as random as their positions.
  const bool flip = D < 0;
  t.v[0] = va;
  t.v[1] = flip ? vc : vb;
  t.v[2] = flip ? vb : vc;
  D = flip ? -D : D;
  for (auto& v : t.v) {
    v.x &= keep;
    v.y &= keep;
  }
  std::copy(std::begin(va.c), std::end(va.c), t.flat);
  const auto [mnx, mxx] = std::minmax({t.v[0].x, t.v[1].x, t.v[2].x});
  const auto [mny, mxy] = std::minmax({t.v[0].y, t.v[1].y, t.v[2].y});
  // Pixels whose sample point 16x + 8 lies inside the vertices' extent.
  t.x0 = std::max<std::int64_t>(state.clip.x0, ceil_div(std::int64_t{mnx} - 8, 16));
  t.x1 = std::min<std::int64_t>(state.clip.x1, floor_div(std::int64_t{mxx} - 8, 16) + 1);
  t.y0 = std::max<std::int64_t>(state.clip.y0, ceil_div(std::int64_t{mny} - 8, 16));
  t.y1 = std::min<std::int64_t>(state.clip.y1, floor_div(std::int64_t{mxy} - 8, 16) + 1);
  if (t.x0 >= t.x1 || t.y0 >= t.y1) return false;

  t.den = 2 * D;
  const std::int64_t sx = 16 * std::int64_t{t.x0} + 8, sy = 16 * std::int64_t{t.y0} + 8;
  // Raw edge functions (the barycentric weights of the planes) and, in t.edge, the biased ones.
  const Edge e20 = make_edge(t.v[2], t.v[0], sx, sy);
  const Edge e01 = make_edge(t.v[0], t.v[1], sx, sy);
  t.edge[0] = make_edge(t.v[1], t.v[2], sx, sy);
  t.edge[0].e += edge_bias(t.v[1], t.v[2]);
  t.edge[1] = {e20.e + edge_bias(t.v[2], t.v[0]), e20.ex, e20.ey};
  t.edge[2] = {e01.e + edge_bias(t.v[0], t.v[1]), e01.ex, e01.ey};

  const Vertex* v = t.v;
  const Divider div(t.den);
  const bool color = all_attributes || state.gouraud;
  const bool depth = all_attributes || state.z_test || state.z_write;
  const bool tex = all_attributes || state.textured;
  // Planes not set up read as constant (the kernels never step them).
  if (color)
    setup_color_planes(&t.plane[kR], v, e20, e01, D);
  else
    for (unsigned ch = 0; ch < 4; ++ch) t.plane[kR + ch] = Plane{};
  if (depth) setup_plane(t.plane[kZ], v[0].z, v[1].z, v[2].z, e20, e01, D, div);
  else t.plane[kZ] = Plane{};
  if (tex) {
    setup_plane(t.plane[kS], v[0].s, v[1].s, v[2].s, e20, e01, D, div);
    setup_plane(t.plane[kT], v[0].t, v[1].t, v[2].t, e20, e01, D, div);
    setup_plane(t.plane[kQ], v[0].q, v[1].q, v[2].q, e20, e01, D, div);
  } else {
    t.plane[kS] = t.plane[kT] = t.plane[kQ] = Plane{};
  }
  return true;
}

}  // namespace gpubridge::sim
