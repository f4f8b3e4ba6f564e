#include "setup.hpp"

#include "color_planes.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
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

namespace {

// Section 8: D, the exchange, the clipped box and the biased edge functions (shared by the exact
// and the preview setup). Returns the raw edge functions e20, e01 (the barycentric weights of
// vertices 1 and 2 at the box origin's sample point) and D.
bool setup_coverage(const Vertex& va, const Vertex& vb, const Vertex& vc, const DrawState& state,
                    unsigned subpixel_bits, Triangle& t, Edge& e20, Edge& e01, std::int64_t& area) {
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
  area = D;
  const std::int64_t sx = 16 * std::int64_t{t.x0} + 8, sy = 16 * std::int64_t{t.y0} + 8;
  // Raw edge functions (the barycentric weights of the planes) and, in t.edge, the biased ones.
  e20 = make_edge(t.v[2], t.v[0], sx, sy);
  e01 = make_edge(t.v[0], t.v[1], sx, sy);
  t.edge[0] = make_edge(t.v[1], t.v[2], sx, sy);
  t.edge[0].e += edge_bias(t.v[1], t.v[2]);
  t.edge[1] = {e20.e + edge_bias(t.v[2], t.v[0]), e20.ex, e20.ey};
  t.edge[2] = {e01.e + edge_bias(t.v[0], t.v[1]), e01.ex, e01.ey};
  return true;
}

// One attribute as a plane a(kx, ky) = base + kx·dx + ky·dy over the box (kx, ky relative to its
// origin) in double, from the same barycentric weights as the exact plane. `offset` is added to
// base (0.5 for values rounded by truncation).
[[gnu::always_inline]] inline void setup_float_plane(FloatPlanes& f, unsigned i, double a0, double a1, double a2, const Edge& b1, const Edge& b2,
                       double inv_d, double offset) {
  const double d1 = a1 - a0, d2 = a2 - a0;
  f.base[i] = a0 + (d1 * static_cast<double>(b1.e) + d2 * static_cast<double>(b2.e)) * inv_d + offset;
  f.dx[i] = (d1 * static_cast<double>(b1.ex) + d2 * static_cast<double>(b2.ex)) * inv_d;
  f.dy[i] = (d1 * static_cast<double>(b1.ey) + d2 * static_cast<double>(b2.ey)) * inv_d;
}

// round_mod64(x) modulo 2^32 for the colour planes: below 2^50 in magnitude (all but extreme
// slivers) one add puts round(x) (to nearest, ties to even) in the low bits of a double whose unit
// is 1, with no conversion at all.
inline std::uint32_t round_mod32(double x) {
  if (x > -0x1p50 && x < 0x1p50) {
    const double m = x + 0x1.8p52;
    std::uint64_t bits;
    std::memcpy(&bits, &m, sizeof bits);
    return static_cast<std::uint32_t>(bits);  // 2^51 + round(x) in the mantissa; 2^51 is 0 modulo 2^32
  }
  return static_cast<std::uint32_t>(round_mod64(x));
}

// The planes of an untextured preview draw in the fixed point of the plain kernel (setup.hpp).
void setup_fixed_planes(const FloatPlanes& f, const DrawState& state, const Triangle& t, FixedPlanes& x) {
  for (unsigned ch = 0; ch < 4; ++ch) {
    if (state.gouraud) {
      x.c[ch] = round_mod32(f.base[kR + ch] * 0x1p24);
      x.cdx[ch] = round_mod32(f.dx[kR + ch] * 0x1p24);
      x.cdy[ch] = round_mod32(f.dy[kR + ch] * 0x1p24);
    } else {  // the flat colour: its byte and a half, no steps
      x.c[ch] = (std::uint32_t{t.flat[ch]} << 24) | 0x800000u;
      x.cdx[ch] = x.cdy[ch] = 0;
    }
  }
  if (state.z_test || state.z_write) {
    x.z = round_mod64(f.base[kZ] * 0x1p32);
    x.zdx = round_mod64(f.dx[kZ] * 0x1p32);
    x.zdy = round_mod64(f.dy[kZ] * 0x1p32);
  }
}

}  // namespace

bool setup_triangle(const Vertex& va, const Vertex& vb, const Vertex& vc, const DrawState& state,
                    unsigned subpixel_bits, bool all_attributes, Triangle& t) {
  Edge e20, e01;
  std::int64_t D = 0;
  if (!setup_coverage(va, vb, vc, state, subpixel_bits, t, e20, e01, D)) return false;
  t.preview = false;
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

bool setup_triangle_preview(const Vertex& va, const Vertex& vb, const Vertex& vc, const DrawState& state,
                            unsigned subpixel_bits, bool observing, Triangle& t) {
  Edge e20, e01;  // the raw weights of vertices 1 and 2 at the box origin's sample point
  if (observing) {  // the observer reports the exact interpolants: set those up too
    if (!setup_triangle(va, vb, vc, state, subpixel_bits, true, t)) return false;
    // setup_triangle does not return the raw weights: cheap integer products.
    const std::int64_t sx = 16 * std::int64_t{t.x0} + 8, sy = 16 * std::int64_t{t.y0} + 8;
    e20 = make_edge(t.v[2], t.v[0], sx, sy);
    e01 = make_edge(t.v[0], t.v[1], sx, sy);
  } else {
    std::int64_t D = 0;
    if (!setup_coverage(va, vb, vc, state, subpixel_bits, t, e20, e01, D)) return false;
    // The preview routine reads only whether the colours differ and the flat colour (t.flat).
    for (unsigned ch = 0; ch < 4; ++ch) {
      t.plane[kR + ch].constant = va.c[ch] == vb.c[ch] && va.c[ch] == vc.c[ch];
      t.plane[kR + ch].q = va.c[ch];
    }
  }
  const Vertex* v = t.v;
  const double inv_d = 2.0 / static_cast<double>(t.den);  // 1 / D: the setup's one float divide
  FloatPlanes& f = t.fplane;
  if (state.gouraud)
    for (unsigned ch = 0; ch < 4; ++ch) setup_float_plane(f, kR + ch, v[0].c[ch], v[1].c[ch], v[2].c[ch], e20, e01, inv_d, 0.5);
  if (state.z_test || state.z_write) setup_float_plane(f, kZ, v[0].z, v[1].z, v[2].z, e20, e01, inv_d, 0.5);
  if (state.textured) {
    setup_float_plane(f, kS, v[0].s, v[1].s, v[2].s, e20, e01, inv_d, 0.0);
    setup_float_plane(f, kT, v[0].t, v[1].t, v[2].t, e20, e01, inv_d, 0.0);
    setup_float_plane(f, kQ, v[0].q, v[1].q, v[2].q, e20, e01, inv_d, 0.0);
  }
  setup_fixed_planes(f, state, t, t.xplane);  // colour and Z of the plain kernel (textured too)
  t.preview = true;
  return true;
}

}  // namespace gpubridge::sim
