// The whole host pipeline: guard band (nothing outside the 12.4 range, coverage preserved),
// near clipping through a perspective camera, texture-precision subdivision without
// T-junctions, culling, and rejection of non-finite input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <set>

#include "gpubridge/geometry/pipeline.hpp"

namespace gpubridge::geometry {
namespace {

Vertex screen(double x, double y, double z = 0.5, double w = 1, Vec2 uv = {}) {
  ScreenVertex s;
  s.x = x;
  s.y = y;
  s.z = z;
  s.w = w;
  s.uv = uv;
  return from_screen(s);
}

// Point-in-triangle with a margin, in double precision, independent of the pipeline.
// Returns +1 inside by more than `margin` px, -1 outside by more than `margin`, 0 near an edge.
int classify(const std::array<Vec2, 3>& t, Vec2 p, double margin) {
  const double area = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y);
  const double sign = area < 0 ? -1 : 1;
  double min_dist = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    const Vec2 a = t[i], b = t[(i + 1) % 3];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const double e = sign * ((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)) / len;
    min_dist = std::min(min_dist, e);
  }
  return min_dist > margin ? 1 : min_dist < -margin ? -1 : 0;
}

std::array<Vec2, 3> pixels(const DeviceTriangle& t) {
  std::array<Vec2, 3> p;
  for (int i = 0; i < 3; ++i) p[i] = {t[i].x / 16.0, t[i].y / 16.0};
  return p;
}

TEST(Pipeline, GuardBandKeepsEverythingInRangeAndPreservesCoverage) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> huge(-1e6, 1e6), window(-2000, 2000);
  PipelineOptions opt;
  for (int n = 0; n < 300; ++n) {
    std::array<Vec2, 3> in{Vec2{huge(rng), huge(rng)}, Vec2{window(rng), window(rng)}, Vec2{huge(rng), huge(rng)}};
    if (n % 3 == 0) in[1] = {huge(rng), huge(rng)};
    const Triangle t{screen(in[0].x, in[0].y), screen(in[1].x, in[1].y), screen(in[2].x, in[2].y)};
    std::vector<DeviceTriangle> out;
    const auto r = process_triangle(t, opt, out);
    ASSERT_TRUE(r) << r.error().message;
    for (const auto& d : out)
      for (const auto& v : d) {
        EXPECT_GE(v.x / 16.0, opt.guard_band.min - 1.0 / 32);
        EXPECT_LE(v.x / 16.0, opt.guard_band.max + 1.0 / 32);
        EXPECT_GE(v.y / 16.0, opt.guard_band.min - 1.0 / 32);
        EXPECT_LE(v.y / 16.0, opt.guard_band.max + 1.0 / 32);
      }
    // Coverage inside the band is unchanged (up to snapping: vertices move ≤ 1/32 px; clipping
    // round-off at 1e6 px is ~1e-9 px).
    for (int k = 0; k < 200; ++k) {
      const Vec2 p{window(rng), window(rng)};
      const int expected = classify(in, p, 0.1);
      if (expected == 0) continue;
      int covered = 0;
      for (const auto& d : out) covered += classify(pixels(d), p, 0.0) > 0;
      EXPECT_EQ(covered, expected > 0 ? 1 : 0) << "triangle " << n << " point " << p.x << "," << p.y;
    }
  }
}

TEST(Pipeline, RandomCameraTrianglesNeverFailAndStayInRange) {
  // Triangles around and behind a perspective camera, including vertices at the eye.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> coord(-50, 50);
  const Mat4 m = viewport_matrix({0, 0, 640, 480}) * perspective(1.2, 640.0 / 480, 0.1, 1000);
  PipelineOptions opt;
  opt.textured = true;
  std::size_t emitted = 0, clipped = 0;
  PipelineStats st;
  for (int n = 0; n < 3000; ++n) {
    Triangle t;
    for (auto& v : t) {
      v.pos = m * Vec4{coord(rng), coord(rng), coord(rng), 1};
      v.uv = {coord(rng) / 20, coord(rng) / 20};
    }
    if (n % 50 == 0) t[0].pos = m * Vec4{0, 0, 0, 1};  // exactly at the eye: W = 0
    std::vector<DeviceTriangle> out;
    const auto r = process_triangle(t, opt, out, &st);
    ASSERT_TRUE(r) << n << ": " << r.error().message;
    for (const auto& d : out) {
      for (const auto& v : d) {
        EXPECT_LE(std::abs(v.x / 16.0), 2047.0 + 1.0 / 32);
        EXPECT_LE(std::abs(v.y / 16.0), 2047.0 + 1.0 / 32);
        EXPECT_GT(v.q, 0u);
      }
    }
    emitted += out.size();
  }
  clipped = st.clipped;
  EXPECT_GT(emitted, 1000u);  // the test exercises real output...
  EXPECT_GT(clipped, 500u);   // ...and real clipping
  EXPECT_GT(st.clipped_away, 100u);
}

TEST(Pipeline, NearClipThroughCameraGivesTwoTriangles) {
  const Mat4 m = viewport_matrix({0, 0, 640, 480}) * perspective(std::numbers::pi / 2, 640.0 / 480, 1, 100);
  // A floor triangle running from behind the camera to in front of it.
  Triangle t;
  t[0].pos = m * Vec4{0, -1, 5, 1};   // behind the eye
  t[1].pos = m * Vec4{1, -1, -10, 1};
  t[2].pos = m * Vec4{-1, -1, -10, 1};
  std::vector<DeviceTriangle> out;
  PipelineStats st;
  ASSERT_TRUE(process_triangle(t, PipelineOptions{}, out, &st));
  EXPECT_EQ(out.size(), 2u);
  EXPECT_EQ(st.clipped, 1u);
  // Every emitted depth is in front of or on the near plane, and the new vertices are at depth 0.
  int at_near = 0;
  for (const auto& d : out)
    for (const auto& v : d) at_near += v.z == 0;
  EXPECT_GE(at_near, 2);
}

TEST(Pipeline, SubdivisionMeetsPrecisionBoundWithoutTJunctions) {
  // A textured quad (two triangles sharing the diagonal 0-2) seen at a grazing angle: W from 1
  // to 1000 and U up to 20 texture widths.
  const Vertex p0 = screen(100, 400, 0.1, 1, {0, 0}), p1 = screen(500, 400, 0.1, 1, {20, 0});
  const Vertex p2 = screen(330, 100, 0.9, 1000, {20, 20}), p3 = screen(310, 100, 0.9, 1000, {0, 20});
  PipelineOptions opt;
  opt.textured = true;
  opt.max_subdivision_depth = 12;
  std::vector<DeviceTriangle> a, b;
  PipelineStats st;
  ASSERT_TRUE(process_triangle({p0, p1, p2}, opt, a, &st));
  ASSERT_TRUE(process_triangle({p0, p2, p3}, opt, b, &st));
  EXPECT_GT(st.subdivided, 0u);
  EXPECT_EQ(st.precision_exceeded, 0u);
  for (const auto* list : {&a, &b})
    for (const auto& d : *list) {
      std::uint32_t qmin = 0xFFFFFFFFu;
      double umin = 1e9, umax = -1e9;
      for (const auto& v : d) {
        qmin = std::min(qmin, v.q);
        const double u = v.s * 256.0 / v.q;  // recovered u − u_off
        umin = std::min(umin, u);
        umax = std::max(umax, u);
        EXPECT_LT(std::abs(u), 4.0 + 1e-6);
      }
      EXPECT_GE(qmin, 4294967295.0 / opt.max_w_ratio - 1);
      EXPECT_LE(umax - umin, opt.max_uv_extent + 1e-6);
    }
  // Vertices on the shared diagonal (snapped) must be the same set in both halves.
  auto on_diagonal = [&](const std::vector<DeviceTriangle>& list) {
    std::set<std::pair<int, int>> pts;
    const double x0 = 100 * 16, y0 = 400 * 16, x2 = 330 * 16, y2 = 100 * 16;
    for (const auto& d : list)
      for (const auto& v : d) {
        const double cross = (x2 - x0) * (v.y - y0) - (y2 - y0) * (v.x - x0);
        // On the diagonal: within snapping distance of it, and not in the corners where the
        // other edges come that close too.
        const bool near_end = std::hypot(v.x - x0, v.y - y0) < 64 || std::hypot(v.x - x2, v.y - y2) < 64;
        if (!near_end && std::abs(cross) / std::hypot(x2 - x0, y2 - y0) < 0.75) pts.insert({v.x, v.y});
      }
    return pts;
  };
  const auto da = on_diagonal(a), db = on_diagonal(b);
  EXPECT_GT(da.size(), 2u);
  EXPECT_EQ(da, db);
}

TEST(Pipeline, SubdivisionDepthLimitIsReportedNotSilent) {
  PipelineOptions opt;
  opt.textured = true;
  opt.max_subdivision_depth = 1;
  std::vector<DeviceTriangle> out;
  PipelineStats st;
  ASSERT_TRUE(process_triangle({screen(0, 0, 0.5, 1), screen(100, 0, 0.5, 1e5), screen(0, 100, 0.5, 1)}, opt, out, &st));
  EXPECT_GT(st.precision_exceeded, 0u);
  // Without texturing no subdivision happens.
  opt.textured = false;
  out.clear();
  PipelineStats st2;
  ASSERT_TRUE(process_triangle({screen(0, 0, 0.5, 1), screen(100, 0, 0.5, 1e5), screen(0, 100, 0.5, 1)}, opt, out, &st2));
  EXPECT_EQ(out.size(), 1u);
  EXPECT_EQ(st2.subdivided, 0u);
}

TEST(Pipeline, TextureRangeBeyondSubdivisionIsAnError) {
  PipelineOptions opt;
  opt.textured = true;
  opt.tex = {protocol::Wrap::Clamp, protocol::Wrap::Clamp};
  std::vector<DeviceTriangle> out;
  const auto r = process_triangle({screen(0, 0, 0.5, 1, {500, 0}), screen(10, 0, 0.5, 1, {501, 0}),
                                   screen(0, 10, 0.5, 1, {500, 1})}, opt, out);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("texture coordinate"), std::string::npos);
}

TEST(Pipeline, CullingByScreenWinding) {
  // On screen (y down): (0,0) → (0,10) → (10,0) turns counter-clockwise as seen.
  const Triangle ccw{screen(0, 0), screen(0, 10), screen(10, 0)};
  const Triangle cw{screen(0, 0), screen(10, 0), screen(0, 10)};
  PipelineOptions opt;
  opt.cull = CullMode::Back;
  std::vector<DeviceTriangle> out;
  ASSERT_TRUE(process_triangle(ccw, opt, out));
  EXPECT_EQ(out.size(), 1u);
  ASSERT_TRUE(process_triangle(cw, opt, out));
  EXPECT_EQ(out.size(), 1u);
  opt.front_face = FrontFace::Clockwise;
  ASSERT_TRUE(process_triangle(cw, opt, out));
  EXPECT_EQ(out.size(), 2u);
  opt.cull = CullMode::Front;
  ASSERT_TRUE(process_triangle(cw, opt, out));
  EXPECT_EQ(out.size(), 2u);
  opt.cull = CullMode::None;
  ASSERT_TRUE(process_triangle(cw, opt, out));
  ASSERT_TRUE(process_triangle(ccw, opt, out));
  EXPECT_EQ(out.size(), 4u);
}

TEST(Pipeline, ZeroAreaAfterSnappingIsDropped) {
  std::vector<DeviceTriangle> out;
  PipelineStats st;
  // All three vertices snap to the same 1/16 grid point.
  ASSERT_TRUE(process_triangle({screen(5, 5), screen(5.01, 5), screen(5, 5.01)}, PipelineOptions{}, out, &st));
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(st.culled, 1u);
}

TEST(Pipeline, RejectsNonFiniteInput) {
  const double bad[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                        -std::numeric_limits<double>::infinity()};
  for (double b : bad) {
    for (int field = 0; field < 4; ++field) {
      Triangle t{screen(0, 0), screen(10, 0), screen(0, 10)};
      if (field == 0) t[1].pos.x = b;
      if (field == 1) t[2].pos.w = b;
      if (field == 2) t[0].color.y = b;
      if (field == 3) t[0].uv.x = b;
      std::vector<DeviceTriangle> out;
      const auto r = process_triangle(t, PipelineOptions{}, out);
      EXPECT_FALSE(r) << field;
      EXPECT_TRUE(out.empty());
    }
  }
}

// A snapping tie x = k/16 + 1/32 and a w for which x·w / w comes back one ulp below x, so that
// snapping the divided value rounds down where floor(16·x + 0.5) rounds up.
struct TieCase {
  double x, w;
};
TieCase tie_below_after_round_trip() {
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> w(0.25, 8.0);
  for (int k = 100;; ++k) {
    const double x = (k + 0.5) / 16.0;
    for (int i = 0; i < 64; ++i) {
      const double ww = w(rng);
      if ((x * ww) / ww < x) return {x, ww};
    }
  }
}

std::set<std::int16_t> sent_x(const std::vector<DeviceTriangle>& out) {
  std::set<std::int16_t> xs;
  for (const auto& t : out)
    for (const auto& v : t) xs.insert(v.x);
  return xs;
}

// docs/protocol.md 16.2: a vertex given in screen space is snapped from the x given, whatever w is;
// only homogeneous input is snapped from X / W.
TEST(Pipeline, ScreenVertexOnATieSnapsFromTheGivenXWhateverW) {
  const TieCase c = tie_below_after_round_trip();
  const auto rule = static_cast<std::int16_t>(std::floor(16.0 * c.x + 0.5));
  ScreenVertex a, b, d;
  a.x = c.x, a.y = 10.03125, a.z = 0.25, a.w = c.w;
  b.x = c.x + 20, b.y = 10, b.z = 0.5, b.w = 2;
  d.x = c.x, d.y = 30, d.z = 0.75, d.w = 3;
  std::vector<DeviceTriangle> out;
  ASSERT_TRUE(process_screen_triangle({a, b, d}, PipelineOptions{}, out));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0][0].x, rule) << "x = " << c.x << ", w = " << c.w;
  EXPECT_EQ(out[0][0].y, 161);  // 10.03125: a tie in y too
  EXPECT_EQ(out[0][0].z, static_cast<std::uint32_t>(std::floor(0.25 * 16777215.0 + 0.5)));
  // The same point in homogeneous form is snapped from its divide, one ulp below the tie.
  std::vector<DeviceTriangle> homogeneous;
  ASSERT_TRUE(process_triangle({from_screen(a), from_screen(b), from_screen(d)}, PipelineOptions{}, homogeneous));
  EXPECT_EQ(homogeneous[0][0].x, rule - 1) << "the search should have found a round trip that loses the tie";
}

// A vertex of a clipped triangle that no plane cut away keeps the user's x; the new vertices are
// snapped from their X / W (section 16.2).
TEST(Pipeline, ClippedTriangleKeepsTheGivenXOfItsSurvivingVertices) {
  const TieCase c = tie_below_after_round_trip();
  const auto rule = static_cast<std::int16_t>(std::floor(16.0 * c.x + 0.5));
  ScreenVertex a, b, d;
  a.x = c.x, a.y = 10, a.z = 0.5, a.w = c.w;
  b.x = c.x + 40, b.y = 10, b.z = -0.5, b.w = 1;  // behind the near plane: the triangle is clipped
  d.x = c.x, d.y = 50, d.z = 0.5, d.w = 2;
  std::vector<DeviceTriangle> out;
  PipelineStats st;
  ASSERT_TRUE(process_screen_triangle({a, b, d}, PipelineOptions{}, out, &st));
  EXPECT_EQ(st.clipped, 1u);
  ASSERT_FALSE(out.empty());
  EXPECT_TRUE(sent_x(out).contains(rule)) << "x = " << c.x << ", w = " << c.w;
  EXPECT_FALSE(sent_x(out).contains(static_cast<std::int16_t>(rule - 1)));
}

// Texture-precision subdivision (W ratio 64) keeps the corners the user gave exact.
TEST(Pipeline, SubdividedTriangleKeepsTheGivenXOfItsCorners) {
  const TieCase c = tie_below_after_round_trip();
  const auto rule = static_cast<std::int16_t>(std::floor(16.0 * c.x + 0.5));
  ScreenVertex a, b, d;
  a.x = c.x, a.y = 10, a.z = 0.5, a.w = c.w;
  b.x = c.x + 40, b.y = 12, b.z = 0.5, b.w = c.w * 64;
  d.x = c.x + 3, d.y = 50, d.z = 0.5, d.w = c.w;
  PipelineOptions opt;
  opt.textured = true;
  std::vector<DeviceTriangle> out;
  PipelineStats st;
  ASSERT_TRUE(process_screen_triangle({a, b, d}, opt, out, &st));
  EXPECT_GE(st.subdivided, 1u);
  EXPECT_TRUE(sent_x(out).contains(rule)) << "x = " << c.x << ", w = " << c.w;
  EXPECT_FALSE(sent_x(out).contains(static_cast<std::int16_t>(rule - 1)));
}

// x and w finite but x·w not: an error, not Inf in the pipeline.
TEST(Pipeline, ScreenVertexWhoseHomogeneousFormOverflowsIsAnError) {
  ScreenVertex a, b, d;
  a.x = 1e300, a.w = 1e300;
  b.x = 10, d.y = 10;
  std::vector<DeviceTriangle> out;
  const auto r = process_screen_triangle({a, b, d}, PipelineOptions{}, out);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("vertex 0: NaN or Inf"), std::string::npos) << r.error().message;
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace gpubridge::geometry
