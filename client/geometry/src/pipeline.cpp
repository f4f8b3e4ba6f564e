#include "gpubridge/geometry/pipeline.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace gpubridge::geometry {
namespace {

bool finite(const Vertex& v) {
  for (double a : {v.pos.x, v.pos.y, v.pos.z, v.pos.w, v.color.x, v.color.y, v.color.z, v.color.w, v.uv.x, v.uv.y})
    if (!std::isfinite(a)) return false;
  return true;
}

bool finite(const ScreenVertex& v) {
  for (double a : {v.x, v.y, v.z, v.w, v.color.x, v.color.y, v.color.z, v.color.w, v.uv.x, v.uv.y})
    if (!std::isfinite(a)) return false;
  return true;
}

Error not_finite(int vertex) {
  return make_error(fmt::format("vertex {}: NaN or Inf in position, colour or texture coordinate "
                                "(every value must be a finite number)", vertex));
}

// Whether edge a-b needs splitting for texture precision. Depends only on the two endpoints
// (and symmetrically on them), so both triangles sharing the edge decide the same.
bool edge_over_bound(const Vertex& a, const Vertex& b, const PipelineOptions& opt, double w_ratio) {
  const double wmin = std::min(a.pos.w, b.pos.w), wmax = std::max(a.pos.w, b.pos.w);
  if (wmax > w_ratio * wmin) return true;
  return std::fabs(a.uv.x - b.uv.x) > opt.max_uv_extent || std::fabs(a.uv.y - b.uv.y) > opt.max_uv_extent;
}

// Homogeneous midpoint, computed as a symmetric function of the endpoints.
Vertex midpoint(const Vertex& a, const Vertex& b) {
  return Vertex{(a.pos + b.pos) * 0.5, (a.color + b.color) * 0.5, (a.uv + b.uv) * 0.5};
}

// The screen vertices the user gave (scene files, draw_screen) beside the window-homogeneous form
// the pipeline clips and subdivides. A vertex is snapped from its perspective divide unless it is
// one the user gave: then from the user's own x, y and z, because x·w / w need not give x back,
// and on a snapping tie (x = k/16 + 1/32) one ulp moves the vertex by 1/16 px (docs/protocol.md
// 16.2). Clipping and subdivision copy the vertices they keep, so "one the user gave" is exact
// equality with its homogeneous form (position, colour and texture coordinates); new vertices
// (intersections, midpoints) never equal one unless they are that point. Two given vertices with
// the same homogeneous form (a zero-length edge) are both snapped from the first one's x.
struct GivenScreen {
  const std::array<ScreenVertex, 3>& screen;
  const Triangle& homogeneous;

  void apply(const Vertex& v, ScreenVertex& s) const {
    for (int i = 0; i < 3; ++i)
      if (homogeneous[i] == v) {
        s.x = screen[i].x;
        s.y = screen[i].y;
        s.z = screen[i].z;
        return;
      }
  }
};

class Emitter {
 public:
  Emitter(const PipelineOptions& opt, std::vector<DeviceTriangle>& out, PipelineStats& st,
          const GivenScreen* given = nullptr)
      : opt_(opt), out_(out), st_(st), given_(given) {
    // The texel error terms that grow with the W ratio are proportional to the texture size
    // (docs/protocol.md section 15), so smaller textures tolerate proportionally larger ratios.
    const unsigned size = std::clamp(opt.texture_size, 1u, 1024u);
    w_ratio_ = opt.max_w_ratio * (1024.0 / size);
  }

  Result<void> subdivide(const Triangle& t, unsigned depth) {
    if (!opt_.textured || !opt_.subdivide) return emit(t);
    const bool split[3] = {edge_over_bound(t[0], t[1], opt_, w_ratio_), edge_over_bound(t[1], t[2], opt_, w_ratio_),
                           edge_over_bound(t[2], t[0], opt_, w_ratio_)};
    const int n = split[0] + split[1] + split[2];
    if (n == 0) return emit(t);
    if (depth >= opt_.max_subdivision_depth) {
      ++st_.precision_exceeded;
      return emit(t);
    }
    ++st_.subdivided;
    // Rotate so the first split edge is edge 0 (t0-t1); keeps the winding.
    int r = split[0] ? 0 : split[1] ? 1 : 2;
    const Vertex& a = t[r];
    const Vertex& b = t[(r + 1) % 3];
    const Vertex& c = t[(r + 2) % 3];
    const bool sbc = split[(r + 1) % 3], sca = split[(r + 2) % 3];
    const Vertex mab = midpoint(a, b);
    std::array<Triangle, 4> parts;
    int count = 0;
    if (sbc && sca) {
      const Vertex mbc = midpoint(b, c), mca = midpoint(c, a);
      parts = {Triangle{a, mab, mca}, Triangle{mab, b, mbc}, Triangle{mca, mbc, c}, Triangle{mab, mbc, mca}};
      count = 4;
    } else if (sbc) {
      const Vertex mbc = midpoint(b, c);
      parts[0] = {a, mab, c};
      parts[1] = {mab, b, mbc};
      parts[2] = {mab, mbc, c};
      count = 3;
    } else if (sca) {
      const Vertex mca = midpoint(c, a);
      parts[0] = {a, mab, mca};
      parts[1] = {mab, b, c};
      parts[2] = {mab, c, mca};
      count = 3;
    } else {
      parts[0] = {a, mab, c};
      parts[1] = {mab, b, c};
      count = 2;
    }
    for (int i = 0; i < count; ++i)
      if (auto r2 = subdivide(parts[i], depth + 1); !r2) return r2;
    return {};
  }

 private:
  Result<void> emit(const Triangle& t) {
    std::array<ScreenVertex, 3> s{to_screen(t[0]), to_screen(t[1]), to_screen(t[2])};
    if (given_)
      for (int i = 0; i < 3; ++i) given_->apply(t[i], s[i]);
    if (!opt_.textured)
      for (auto& v : s) v.uv = {};  // S/T are not sent: their range must not limit untextured draws
    auto dev = convert_triangle(s, opt_.tex);
    if (!dev) return dev.error();
    const std::int64_t area = signed_area2(*dev);
    if (area == 0) {
      ++st_.culled;
      return {};
    }
    if (opt_.cull != CullMode::None) {
      const bool ccw = area < 0;
      const bool front = (opt_.front_face == FrontFace::CounterClockwise) == ccw;
      if ((opt_.cull == CullMode::Back && !front) || (opt_.cull == CullMode::Front && front)) {
        ++st_.culled;
        return {};
      }
    }
    if (opt_.visible && covers_no_pixel(*dev, *opt_.visible)) {
      ++st_.outside;
      return {};
    }
    out_.push_back(*dev);
    ++st_.emitted;
    return {};
  }

  const PipelineOptions& opt_;
  std::vector<DeviceTriangle>& out_;
  PipelineStats& st_;
  const GivenScreen* given_;
  double w_ratio_ = 32.0;
};

}  // namespace

std::int64_t signed_area2(const DeviceTriangle& t) {
  const std::int64_t x0 = t[0].x, y0 = t[0].y, x1 = t[1].x, y1 = t[1].y, x2 = t[2].x, y2 = t[2].y;
  return (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
}

PixelRect visible_rect(unsigned width, unsigned height, unsigned sx0, unsigned sy0, unsigned sx1, unsigned sy1) {
  // Every value the registers hold is at most 1024: the casts are exact.
  return PixelRect{static_cast<int>(sx0), static_cast<int>(sy0), static_cast<int>(std::min(width, sx1)),
                   static_cast<int>(std::min(height, sy1))};
}

bool covers_no_pixel(const DeviceTriangle& t, const PixelRect& rect) {
  if (rect.x1 <= rect.x0 || rect.y1 <= rect.y0) return true;
  const std::int64_t min_x = std::min({t[0].x, t[1].x, t[2].x}), max_x = std::max({t[0].x, t[1].x, t[2].x});
  const std::int64_t min_y = std::min({t[0].y, t[1].y, t[2].y}), max_y = std::max({t[0].y, t[1].y, t[2].y});
  // Sample points of the first and last pixel column (row) of the rectangle, in 1/16 pixel.
  const std::int64_t first_x = 16 * std::int64_t{rect.x0} + 8, last_x = 16 * (std::int64_t{rect.x1} - 1) + 8;
  const std::int64_t first_y = 16 * std::int64_t{rect.y0} + 8, last_y = 16 * (std::int64_t{rect.y1} - 1) + 8;
  return max_x < first_x || min_x > last_x || max_y < first_y || min_y > last_y;
}

Vertex from_screen(const ScreenVertex& v) {
  return Vertex{Vec4{v.x * v.w, v.y * v.w, v.z * v.w, v.w}, v.color, v.uv};
}

ScreenVertex to_screen(const Vertex& v) {
  const double inv = 1.0 / v.pos.w;
  return ScreenVertex{v.pos.x * inv, v.pos.y * inv, v.pos.z * inv, v.pos.w, v.color, v.uv};
}

ClippedPolygon clip_for_pipeline(const Triangle& tri, const PipelineOptions& opt, ClipBuffers& buffers) {
  // Planes in the order the seeds' pipeline applies them: the near plane first (Foenix), then
  // the ones that only matter for unusual input. The polygon lives in the input triangle until a
  // plane cuts it, then alternates between the two buffers: no pass copies a whole polygon.
  ClippedPolygon r{{tri.data(), tri.size()}, false};
  auto clip = [&](Vec4 plane, double offset = 0.0) {
    ClipBuffer& target = r.polygon.v == buffers.a.v ? buffers.b : buffers.a;
    const PolygonView next = clip_polygon_view(r.polygon, plane, offset, target);
    r.clipped |= next.v != r.polygon.v;
    r.polygon = next;
  };
  clip(kNearPlane);
  if (opt.clip_far && r.polygon.count) clip(kFarPlane);
  if (r.polygon.count) clip(Vec4{0, 0, 0, 1}, -opt.min_w);  // W - min_w >= 0
  if (r.polygon.count) {
    bool inside = true;
    for (std::size_t i = 0; i < r.polygon.count && inside; ++i) {
      const Vec4& p = r.polygon.v[i].pos;
      const double x = p.x / p.w, y = p.y / p.w;
      inside = x >= opt.guard_band.min && x <= opt.guard_band.max && y >= opt.guard_band.min && y <= opt.guard_band.max;
    }
    if (!inside)
      for (const Vec4& plane : guard_band_planes(opt.guard_band))
        if (r.polygon.count) clip(plane);
  }
  return r;
}

namespace {

// The pipeline after the input checks; `given` (screen-space input only) as in GivenScreen.
Result<void> run_pipeline(const Triangle& tri, const GivenScreen* given, const PipelineOptions& opt,
                          std::vector<DeviceTriangle>& out, PipelineStats& st) {
  Emitter emitter(opt, out, st, given);
  // Fast path (the common case): every vertex strictly inside every plane, nothing to clip.
  bool all_inside = true;
  for (const auto& v : tri) {
    const Vec4& p = v.pos;
    all_inside = all_inside && p.z >= 0 && (!opt.clip_far || p.z <= p.w) && p.w >= opt.min_w &&
                 p.x >= opt.guard_band.min * p.w && p.x <= opt.guard_band.max * p.w &&
                 p.y >= opt.guard_band.min * p.w && p.y <= opt.guard_band.max * p.w;
  }
  if (all_inside) return emitter.subdivide(tri, 0);

  ClipBuffers buffers;
  const ClippedPolygon c = clip_for_pipeline(tri, opt, buffers);
  const PolygonView poly = c.polygon;
  if (poly.count == 0) {
    ++st.clipped_away;
    return {};
  }
  if (c.clipped) ++st.clipped;

  for (std::size_t i = 1; i + 1 < poly.count; ++i)
    if (auto r = emitter.subdivide(Triangle{poly.v[0], poly.v[i], poly.v[i + 1]}, 0); !r) return r;
  return {};
}

}  // namespace

Result<void> process_triangle(const Triangle& tri, const PipelineOptions& opt, std::vector<DeviceTriangle>& out,
                              PipelineStats* stats) {
  PipelineStats local;
  PipelineStats& st = stats ? *stats : local;
  ++st.input;
  for (int i = 0; i < 3; ++i)
    if (!finite(tri[i])) return not_finite(i);
  return run_pipeline(tri, nullptr, opt, out, st);
}

Result<void> process_screen_triangle(const std::array<ScreenVertex, 3>& tri, const PipelineOptions& opt,
                                     std::vector<DeviceTriangle>& out, PipelineStats* stats) {
  PipelineStats local;
  PipelineStats& st = stats ? *stats : local;
  ++st.input;
  const Triangle homogeneous{from_screen(tri[0]), from_screen(tri[1]), from_screen(tri[2])};
  // x·w can overflow where x and w do not: both forms must be finite.
  for (int i = 0; i < 3; ++i)
    if (!finite(tri[i]) || !finite(homogeneous[i])) return not_finite(i);
  const GivenScreen given{tri, homogeneous};
  return run_pipeline(homogeneous, &given, opt, out, st);
}

}  // namespace gpubridge::geometry
