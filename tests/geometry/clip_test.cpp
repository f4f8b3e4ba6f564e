// Near-plane clipping (the Foenix approach): every count of vertices behind the plane, vertices
// exactly on it, W → 0, attribute interpolation and crack-free shared edges.
#include <gtest/gtest.h>

#include <algorithm>

#include "gpubridge/geometry/clip.hpp"

namespace gpubridge::geometry {
namespace {

// Clip-space vertex at depth z (Z = z_clip) with attributes that are linear functions of the
// position, so the expected value at any point can be computed independently of the clipper.
Vertex make(double x, double y, double z, double w) {
  Vertex v;
  v.pos = {x, y, z, w};
  v.color = {0.1 + 0.01 * x, 0.2 + 0.02 * y, 0.3 + 0.03 * z, 0.4 + 0.04 * w};
  v.uv = {x - y, 2 * z + w};
  return v;
}

void expect_attributes_linear(const Vertex& v) {
  const Vertex e = make(v.pos.x, v.pos.y, v.pos.z, v.pos.w);
  EXPECT_NEAR(v.color.x, e.color.x, 1e-12);
  EXPECT_NEAR(v.color.y, e.color.y, 1e-12);
  EXPECT_NEAR(v.color.z, e.color.z, 1e-12);
  EXPECT_NEAR(v.color.w, e.color.w, 1e-12);
  EXPECT_NEAR(v.uv.x, e.uv.x, 1e-12);
  EXPECT_NEAR(v.uv.y, e.uv.y, 1e-12);
}

double area_xy(const Triangle& t) {
  return (t[1].pos.x - t[0].pos.x) * (t[2].pos.y - t[0].pos.y) - (t[2].pos.x - t[0].pos.x) * (t[1].pos.y - t[0].pos.y);
}

TEST(Clip, NoVertexBehindKeepsTriangleUnchanged) {
  const Triangle t{make(0, 0, 1, 2), make(1, 0, 1, 2), make(0, 1, 1, 2)};
  const auto r = clip_near(t);
  ASSERT_EQ(r.count, 1u);
  EXPECT_EQ(r.triangles[0], t);
}

TEST(Clip, OneVertexBehindGivesTwoTriangles) {
  const Triangle t{make(0, 0, -1, 1), make(4, 0, 3, 5), make(0, 4, 1, 3)};
  const auto r = clip_near(t);
  ASSERT_EQ(r.count, 2u);
  double total = 0;
  for (std::size_t i = 0; i < r.count; ++i) {
    for (const auto& v : r.triangles[i]) {
      EXPECT_GE(v.pos.z, -1e-15);
      expect_attributes_linear(v);
    }
    // Same winding as the input (positive area in x/y for this input).
    EXPECT_GT(area_xy(r.triangles[i]), 0);
    total += area_xy(r.triangles[i]);
  }
  // The behind vertex is gone; the two new vertices are on the plane.
  int on_plane = 0;
  for (std::size_t i = 0; i < r.count; ++i)
    for (const auto& v : r.triangles[i]) {
      EXPECT_FALSE(v.pos == t[0].pos);
      on_plane += std::abs(v.pos.z) < 1e-12;
    }
  EXPECT_GE(on_plane, 2);
  EXPECT_LT(total, area_xy(t));
}

TEST(Clip, TwoVerticesBehindGivesOneTriangle) {
  const Triangle t{make(0, 0, 2, 3), make(4, 0, -1, 1), make(0, 4, -3, 1)};
  const auto r = clip_near(t);
  ASSERT_EQ(r.count, 1u);
  EXPECT_EQ(r.triangles[0][0], t[0]);
  for (int i = 1; i < 3; ++i) {
    EXPECT_NEAR(r.triangles[0][i].pos.z, 0, 1e-12);
    expect_attributes_linear(r.triangles[0][i]);
  }
  // Edge 0→1 is cut at t = 2/3 (z: 2 → -1), edge 2→0 at 2/5 from vertex 0 (z: 2 → -3).
  EXPECT_NEAR(r.triangles[0][1].pos.x, 4 * 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(r.triangles[0][2].pos.y, 4 * 2.0 / 5.0, 1e-12);
  EXPECT_GT(area_xy(r.triangles[0]), 0);
}

TEST(Clip, AllVerticesBehindGivesNothing) {
  const Triangle t{make(0, 0, -1, 1), make(4, 0, -0.001, 1), make(0, 4, -3, 1)};
  EXPECT_EQ(clip_near(t).count, 0u);
}

TEST(Clip, VertexExactlyOnPlaneIsKeptWithoutNewVertices) {
  // One on the plane, two in front: unchanged.
  const Triangle a{make(0, 0, 0, 1), make(4, 0, 1, 2), make(0, 4, 1, 2)};
  auto r = clip_near(a);
  ASSERT_EQ(r.count, 1u);
  EXPECT_EQ(r.triangles[0], a);
  // One on, one in front, one behind: a single triangle (on-plane vertex, front vertex, cut point).
  const Triangle b{make(0, 0, 0, 1), make(4, 0, 2, 3), make(0, 4, -2, 1)};
  r = clip_near(b);
  ASSERT_EQ(r.count, 1u);
  EXPECT_EQ(r.triangles[0][0], b[0]);
  EXPECT_EQ(r.triangles[0][1], b[1]);
  EXPECT_NEAR(r.triangles[0][2].pos.z, 0, 1e-12);
  expect_attributes_linear(r.triangles[0][2]);
}

TEST(Clip, TriangleTouchingPlaneFromBehindVanishes) {
  // One vertex on the plane, two behind: no area on the kept side.
  EXPECT_EQ(clip_near(Triangle{make(0, 0, 0, 1), make(4, 0, -1, 1), make(0, 4, -2, 1)}).count, 0u);
  // Two on the plane, one behind: an edge only.
  EXPECT_EQ(clip_near(Triangle{make(0, 0, 0, 1), make(4, 0, 0, 1), make(0, 4, -2, 1)}).count, 0u);
}

TEST(Clip, WApproachingZeroIsClippedToFiniteVertices) {
  // perspective()-style depth: z_clip = (f/(f-n))·(w − n) with n = 0.1, f = 100. A vertex at
  // the eye (w → 0) is behind the near plane; the new vertices sit at w = n, never near 0.
  const double n = 0.1, f = 100, k = f / (f - n);
  for (double w0 : {1e-3, 1e-9, 1e-300, 0.0, -1e-12}) {
    const Triangle t{make(0, 0, k * (w0 - n), w0), make(5, 0, k * (10 - n), 10), make(0, 5, k * (20 - n), 20)};
    const auto r = clip_near(t);
    ASSERT_EQ(r.count, 2u) << w0;
    for (std::size_t i = 0; i < r.count; ++i)
      for (const auto& v : r.triangles[i]) {
        EXPECT_GE(v.pos.w, n - 1e-12) << w0;
        EXPECT_TRUE(std::isfinite(v.pos.x / v.pos.w));
      }
  }
}

TEST(Clip, SharedEdgeGetsBitIdenticalIntersections) {
  // Two triangles sharing edge P-Q (listed in opposite directions), both crossing the plane.
  const Vertex p = make(0.3, 0.1, 0.7, 1.3), q = make(2.9, 1.7, -0.45, 0.9);
  const Triangle a{p, q, make(0, 3, 1, 2)};
  const Triangle b{q, p, make(3, -2, 2, 2)};
  auto collect = [](const ClipResult& r) {
    std::vector<Vec4> out;
    for (std::size_t i = 0; i < r.count; ++i)
      for (const auto& v : r.triangles[i])
        if (v.pos.z == 0 || std::abs(v.pos.z) < 1e-12) out.push_back(v.pos);
    return out;
  };
  const auto ra = collect(clip_near(a)), rb = collect(clip_near(b));
  // The cut of P-Q appears in both, bit for bit.
  bool found = false;
  for (const auto& va : ra)
    for (const auto& vb : rb) found |= va == vb;
  EXPECT_TRUE(found);
}

TEST(Clip, PolygonAgainstGuardBandPlanesStaysInside) {
  GuardBand gb{-100, 100};
  Polygon p = polygon_from(Triangle{make(-500, 0, 0.5, 1), make(500, -300, 0.5, 2), make(20, 900, 0.5, 1.5)});
  for (const auto& plane : guard_band_planes(gb)) p = clip_polygon(p, plane);
  ASSERT_GE(p.count, 3u);
  for (std::size_t i = 0; i < p.count; ++i) {
    EXPECT_LE(std::abs(p.v[i].pos.x / p.v[i].pos.w), 100 + 1e-9);
    EXPECT_LE(std::abs(p.v[i].pos.y / p.v[i].pos.w), 100 + 1e-9);
    expect_attributes_linear(p.v[i]);
  }
}

}  // namespace
}  // namespace gpubridge::geometry
