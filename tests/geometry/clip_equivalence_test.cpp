// The pipeline's copy-free clipping stage (clip_for_pipeline, clip_polygon_view) against the
// algorithm it replaced, kept here verbatim as the reference: a Polygon copied per plane and
// clipped with the original Sutherland–Hodgman pass. Every vertex must agree bit for bit (the
// golden images depend on it), over many random triangles from each kind of input the pipeline
// sees: near-plane crossings, far-plane crossings, W around 0, huge guard-band triangles and
// vertices exactly on a plane.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "gpubridge/geometry/pipeline.hpp"

namespace gpubridge::geometry {
namespace {

// --- reference: the clipper as it was before clip_polygon_view (commit 938ddef) ---
struct RefPolygon {
  std::array<Vertex, Polygon::kCapacity> v{};
  std::size_t count = 0;
};

Vertex ref_intersect(const Vertex& in, double d_in, const Vertex& out, double d_out) {
  const double t = d_in / (d_in - d_out);
  return Vertex{lerp(in.pos, out.pos, t), lerp(in.color, out.color, t), lerp(in.uv, out.uv, t)};
}

RefPolygon ref_clip_polygon(const RefPolygon& in, Vec4 plane, double offset) {
  RefPolygon out;
  if (in.count < 3) return out;
  std::array<double, Polygon::kCapacity> d{};
  bool any_strictly_inside = false, any_outside = false;
  for (std::size_t i = 0; i < in.count; ++i) {
    d[i] = dot(plane, in.v[i].pos) + offset;
    any_strictly_inside |= d[i] > 0;
    any_outside |= d[i] < 0;
  }
  if (!any_strictly_inside && any_outside) return out;
  if (!any_outside) return in;
  for (std::size_t i = 0; i < in.count; ++i) {
    const std::size_t j = (i + 1) % in.count;
    const Vertex& a = in.v[i];
    const Vertex& b = in.v[j];
    if (d[i] >= 0 && out.count < Polygon::kCapacity) out.v[out.count++] = a;
    if ((d[i] > 0 && d[j] < 0) && out.count < Polygon::kCapacity) out.v[out.count++] = ref_intersect(a, d[i], b, d[j]);
    if ((d[i] < 0 && d[j] > 0) && out.count < Polygon::kCapacity) out.v[out.count++] = ref_intersect(b, d[j], a, d[i]);
  }
  if (out.count < 3) out.count = 0;
  return out;
}

struct RefResult {
  RefPolygon poly;
  bool clipped = false;
};

RefResult ref_clip_for_pipeline(const Triangle& tri, const PipelineOptions& opt) {
  RefResult r;
  for (const auto& v : tri) r.poly.v[r.poly.count++] = v;
  auto clip = [&](Vec4 plane, double offset = 0.0) {
    bool outside = false;
    for (std::size_t i = 0; i < r.poly.count && !outside; ++i) outside = dot(plane, r.poly.v[i].pos) + offset < 0;
    if (!outside) return;
    r.clipped = true;
    r.poly = ref_clip_polygon(r.poly, plane, offset);
  };
  clip(kNearPlane);
  if (opt.clip_far && r.poly.count) clip(kFarPlane);
  if (r.poly.count) clip(Vec4{0, 0, 0, 1}, -opt.min_w);
  if (r.poly.count) {
    bool inside = true;
    for (std::size_t i = 0; i < r.poly.count && inside; ++i) {
      const double x = r.poly.v[i].pos.x / r.poly.v[i].pos.w, y = r.poly.v[i].pos.y / r.poly.v[i].pos.w;
      inside = x >= opt.guard_band.min && x <= opt.guard_band.max && y >= opt.guard_band.min && y <= opt.guard_band.max;
    }
    if (!inside)
      for (const Vec4& plane : guard_band_planes(opt.guard_band))
        if (r.poly.count) clip(plane);
  }
  return r;
}
// --- end of reference ---

bool same_bits(const Vertex& a, const Vertex& b) {
  const double x[10] = {a.pos.x, a.pos.y, a.pos.z, a.pos.w, a.color.x, a.color.y, a.color.z, a.color.w, a.uv.x, a.uv.y};
  const double y[10] = {b.pos.x, b.pos.y, b.pos.z, b.pos.w, b.color.x, b.color.y, b.color.z, b.color.w, b.uv.x, b.uv.y};
  return std::memcmp(x, y, sizeof x) == 0;
}

// Compares both paths on one triangle; returns how many planes cut it (for coverage checks).
void expect_same(const Triangle& tri, const PipelineOptions& opt, std::size_t& clipped_count, std::size_t& empty_count) {
  const RefResult ref = ref_clip_for_pipeline(tri, opt);
  ClipBuffers buffers;
  const ClippedPolygon got = clip_for_pipeline(tri, opt, buffers);
  ASSERT_EQ(got.polygon.count, ref.poly.count);
  ASSERT_EQ(got.clipped, ref.clipped);
  for (std::size_t i = 0; i < ref.poly.count; ++i) ASSERT_TRUE(same_bits(got.polygon.v[i], ref.poly.v[i])) << "vertex " << i;
  clipped_count += ref.clipped;
  empty_count += ref.poly.count == 0;
}

Vertex random_vertex(std::mt19937_64& rng, std::uniform_real_distribution<double>& xy,
                     std::uniform_real_distribution<double>& z, std::uniform_real_distribution<double>& w) {
  std::uniform_real_distribution<double> unit(0, 1), uv(-8, 8);
  Vertex v;
  const double ww = w(rng);
  v.pos = {xy(rng) * ww, xy(rng) * ww, z(rng) * ww, ww};
  v.color = {unit(rng), unit(rng), unit(rng), unit(rng)};
  v.uv = {uv(rng), uv(rng)};
  return v;
}

TEST(ClipEquivalence, RandomTrianglesMatchTheOriginalClipperBitForBit) {
  std::mt19937_64 rng(20261121);
  struct Kind {
    std::uniform_real_distribution<double> xy, z, w;
  };
  // Pixel-space x/y, depth z, and W: crossing near/far, W near and below 0, far outside the band.
  Kind kinds[] = {
      {std::uniform_real_distribution<double>(-100, 700), std::uniform_real_distribution<double>(-1, 1),
       std::uniform_real_distribution<double>(0.05, 10)},
      {std::uniform_real_distribution<double>(-100, 700), std::uniform_real_distribution<double>(0.5, 1.5),
       std::uniform_real_distribution<double>(0.1, 10)},
      {std::uniform_real_distribution<double>(-100, 700), std::uniform_real_distribution<double>(-0.5, 1.5),
       std::uniform_real_distribution<double>(-1e-5, 1e-5)},
      {std::uniform_real_distribution<double>(-40000, 40000), std::uniform_real_distribution<double>(-0.2, 1.2),
       std::uniform_real_distribution<double>(0.5, 2)},
      {std::uniform_real_distribution<double>(-5000, 5000), std::uniform_real_distribution<double>(-3, 3),
       std::uniform_real_distribution<double>(-2, 2)},
  };
  PipelineOptions opts[3];
  opts[1].clip_far = false;
  opts[2].guard_band = {-100, 100};
  opts[2].min_w = 0.01;
  std::size_t clipped = 0, empty = 0, total = 0;
  for (auto& k : kinds)
    for (const auto& opt : opts)
      for (int i = 0; i < 4000; ++i) {
        Triangle t{random_vertex(rng, k.xy, k.z, k.w), random_vertex(rng, k.xy, k.z, k.w),
                   random_vertex(rng, k.xy, k.z, k.w)};
        // Every 8th triangle puts a vertex exactly on the near plane, every 8th another on the far plane.
        if (i % 8 == 3) t[1].pos.z = 0;
        if (i % 8 == 5) t[2].pos.z = t[2].pos.w;
        expect_same(t, opt, clipped, empty);
        if (HasFatalFailure()) return;
        ++total;
      }
  // The inputs really exercised the clipper: most triangles were cut, some vanished, some survived.
  EXPECT_GT(clipped, total / 2);
  EXPECT_GT(empty, total / 20);
  EXPECT_LT(empty, total);
}

TEST(ClipEquivalence, PolygonViewReturnsTheInputWhenNothingIsOutside) {
  Triangle t;
  t[0].pos = {0, 0, 0.5, 1};
  t[1].pos = {10, 0, 0.5, 1};
  t[2].pos = {0, 10, 0.5, 1};
  ClipBuffer out;
  const PolygonView r = clip_polygon_view({t.data(), 3}, kNearPlane, 0.0, out);
  EXPECT_EQ(r.v, t.data());
  EXPECT_EQ(r.count, 3u);
  const PolygonView cut = clip_polygon_view({t.data(), 3}, Vec4{-1, 0, 0, 5}, 0.0, out);  // X <= 5
  EXPECT_EQ(cut.v, out.v);
  EXPECT_EQ(cut.count, 4u);
}

}  // namespace
}  // namespace gpubridge::geometry
