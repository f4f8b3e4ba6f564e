// Rejection of triangles that cannot cover a pixel (geometry::covers_no_pixel, the pipeline's
// `visible` rectangle): never a triangle that covers one. Coverage here is an independent
// transcription of docs/protocol.md section 8 (area, exchange, edge functions, top-left rule,
// pixel sample points), not the pipeline's or the simulator's code.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "gpubridge/geometry/pipeline.hpp"

namespace gpubridge::geometry {
namespace {

DeviceVertex at(int x16, int y16) {
  DeviceVertex v;
  v.x = static_cast<std::int16_t>(x16);
  v.y = static_cast<std::int16_t>(y16);
  return v;
}

// Pixels of `rect` the device covers with the snapped triangle (section 8, steps 1-5).
int covered_pixels(DeviceTriangle t, const PixelRect& rect) {
  std::int64_t X[3], Y[3];
  for (int i = 0; i < 3; ++i) X[i] = t[i].x, Y[i] = t[i].y;
  std::int64_t d = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
  if (d == 0) return 0;
  if (d < 0) std::swap(X[1], X[2]), std::swap(Y[1], Y[2]);
  auto edge = [&](int a, int b, std::int64_t sx, std::int64_t sy) {
    const std::int64_t e = (X[b] - X[a]) * (sy - Y[a]) - (Y[b] - Y[a]) * (sx - X[a]);
    const bool top = Y[a] == Y[b] && X[b] > X[a], left = Y[b] < Y[a];
    return e + (top || left ? 0 : -1) >= 0;
  };
  int n = 0;
  for (int y = std::max(0, rect.y0); y < rect.y1; ++y)
    for (int x = std::max(0, rect.x0); x < rect.x1; ++x) {
      const std::int64_t sx = 16 * x + 8, sy = 16 * y + 8;
      n += edge(0, 1, sx, sy) && edge(1, 2, sx, sy) && edge(2, 0, sx, sy);
    }
  return n;
}

TEST(Visible, RectIsTheFramebufferIntersectedWithTheScissor) {
  EXPECT_EQ(visible_rect(320, 240, 0, 0, 1024, 1024), (PixelRect{0, 0, 320, 240}));
  EXPECT_EQ(visible_rect(320, 240, 10, 20, 100, 1024), (PixelRect{10, 20, 100, 240}));
  EXPECT_EQ(visible_rect(320, 240, 400, 0, 1024, 1024), (PixelRect{400, 0, 320, 240}));  // empty
}

TEST(Visible, ATriangleTouchingASamplePointIsKeptOneSixteenthShortIsNot) {
  const PixelRect r{0, 0, 10, 10};
  // Reaching x = 8/16 px, the sample point of column 0: kept (whether it covers pixel (0, 0) is
  // the fill rule's business: here the point lies on its right-hand edges, so it does not).
  EXPECT_FALSE(covers_no_pixel(DeviceTriangle{at(-32, 0), at(8, 8), at(-32, 16)}, r));
  const DeviceTriangle short_of_it{at(-32, 0), at(7, 8), at(-32, 16)};
  EXPECT_TRUE(covers_no_pixel(short_of_it, r));
  EXPECT_EQ(covered_pixels(short_of_it, r), 0);
  // Column 9's sample points are at x = 16·9 + 8 = 152: a left edge there covers them.
  const DeviceTriangle left_edge_on_last_column{at(152, 0), at(200, 0), at(152, 40)};
  EXPECT_FALSE(covers_no_pixel(left_edge_on_last_column, r));
  EXPECT_EQ(covered_pixels(left_edge_on_last_column, r), 2);  // pixels (9, 0) and (9, 1)
  EXPECT_TRUE(covers_no_pixel(DeviceTriangle{at(153, 0), at(200, 0), at(153, 40)}, r));
  // The same for rows: row 9 at y = 152, row 0 at y = 8.
  const DeviceTriangle top_edge_on_last_row{at(0, 152), at(40, 152), at(0, 200)};
  EXPECT_FALSE(covers_no_pixel(top_edge_on_last_row, r));
  EXPECT_EQ(covered_pixels(top_edge_on_last_row, r), 2);  // (0, 9), (1, 9); x = 40 is the vertex on a right edge
  EXPECT_TRUE(covers_no_pixel(DeviceTriangle{at(0, 153), at(40, 153), at(0, 200)}, r));
  EXPECT_TRUE(covers_no_pixel(DeviceTriangle{at(0, -40), at(40, -40), at(40, 7)}, r));
  EXPECT_FALSE(covers_no_pixel(DeviceTriangle{at(0, -40), at(40, -40), at(40, 8)}, r));
}

TEST(Visible, AnEmptyRectangleRejectsEverything) {
  const DeviceTriangle big{at(-2000, -2000), at(30000, 0), at(0, 30000)};
  EXPECT_TRUE(covers_no_pixel(big, PixelRect{5, 0, 5, 10}));
  EXPECT_TRUE(covers_no_pixel(big, PixelRect{0, 7, 10, 3}));
  EXPECT_FALSE(covers_no_pixel(big, PixelRect{0, 0, 1, 1}));
}

TEST(Visible, RejectedTrianglesNeverCoverAPixel) {
  // Random triangles within a few pixels of a rectangle's edges (where the test decides),
  // including slivers and zero-area ones,: a rejected triangle covers nothing of the rectangle.
  std::mt19937_64 rng(21);
  std::uniform_int_distribution<int> coord(-6 * 16, 26 * 16), size(0, 24);
  std::size_t rejected = 0, kept_empty = 0, rejected_near = 0;
  for (int n = 0; n < 20000; ++n) {
    const int x0 = size(rng) % 8, y0 = size(rng) % 8;
    const PixelRect r{x0, y0, x0 + 1 + size(rng) % 14, y0 + 1 + size(rng) % 14};
    // Every other triangle on a half-pixel grid, so that vertices and edges often lie exactly on
    // sample points (x·16 + 8): the cases a bound off by one would get wrong.
    const int step = n % 2 ? 8 : 1;
    auto c = [&] { return coord(rng) / step * step; };
    const DeviceTriangle t{at(c(), c()), at(c(), c()), at(c(), c())};
    const int covered = covered_pixels(t, r);
    if (covers_no_pixel(t, r)) {
      ++rejected;
      ASSERT_EQ(covered, 0) << "triangle " << n;
      // Within one pixel of the rectangle: the cases where rounding the wrong way would show.
      const PixelRect grown{r.x0 - 1, r.y0 - 1, r.x1 + 1, r.y1 + 1};
      rejected_near += !covers_no_pixel(t, grown);
    } else if (covered == 0) {
      ++kept_empty;  // bounding box overlaps but no sample point inside: sent, draws nothing
    }
  }
  EXPECT_GT(rejected, 2000u);
  EXPECT_GT(rejected_near, 500u);
  EXPECT_GT(kept_empty, 0u);  // the test is the bounding box: conservative, never exact coverage
}

Vertex screen(double x, double y, double z = 0.5) { return Vertex{Vec4{x, y, z, 1}, {1, 1, 1, 1}, {}}; }

TEST(Visible, PipelineSkipsOffscreenTrianglesAndCountsThem) {
  PipelineOptions opt;
  opt.visible = PixelRect{0, 0, 320, 240};
  std::vector<DeviceTriangle> out;
  PipelineStats st;
  ASSERT_TRUE(process_triangle({screen(-50, 10), screen(-10, 10), screen(-30, 40)}, opt, out, &st));  // left
  ASSERT_TRUE(process_triangle({screen(330, 10), screen(400, 10), screen(350, 40)}, opt, out, &st));  // right
  ASSERT_TRUE(process_triangle({screen(10, 250), screen(40, 250), screen(20, 300)}, opt, out, &st));  // below
  ASSERT_TRUE(process_triangle({screen(10, -5), screen(40, -5), screen(20, -1)}, opt, out, &st));     // above
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(st.outside, 4u);
  // Straddling an edge, and wholly inside: sent.
  ASSERT_TRUE(process_triangle({screen(-50, 10), screen(10, 10), screen(-30, 40)}, opt, out, &st));
  ASSERT_TRUE(process_triangle({screen(10, 10), screen(40, 10), screen(20, 40)}, opt, out, &st));
  EXPECT_EQ(out.size(), 2u);
  // Back-facing and off-screen: counted as culled, as without a rectangle.
  opt.cull = CullMode::Back;
  ASSERT_TRUE(process_triangle({screen(-50, 10), screen(-10, 10), screen(-30, 40)}, opt, out, &st));  // clockwise
  EXPECT_EQ(st.culled, 1u);
  EXPECT_EQ(st.outside, 4u);
  EXPECT_EQ(st.emitted, 2u);
}

TEST(Visible, HugeCoordinatesAreClippedThenJudged) {
  PipelineOptions opt;
  opt.visible = PixelRect{0, 0, 320, 240};
  std::vector<DeviceTriangle> out;
  PipelineStats st;
  // Covers the whole screen from far outside the 12.4 range: clipped to the guard band, kept.
  ASSERT_TRUE(process_triangle({screen(-1e30, -1e30), screen(1e30, -1e30), screen(0, 1e30)}, opt, out, &st));
  ASSERT_FALSE(out.empty());
  int covered = 0;
  for (const auto& t : out) covered += covered_pixels(t, *opt.visible);
  EXPECT_EQ(covered, 320 * 240);
  // Reaching far out on one side: clipped to the guard band, and what is left is off-screen.
  out.clear();
  ASSERT_TRUE(process_triangle({screen(-1e30, 10), screen(-100, 10), screen(-100, 1e30)}, opt, out, &st));
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(st.clipped, 2u);
  EXPECT_GT(st.outside, 0u);
  // Wholly beyond the guard band: clipped away before it is judged.
  ASSERT_TRUE(process_triangle({screen(-1e30, 0), screen(-1e29, 0), screen(-1e29, 1e30)}, opt, out, &st));
  EXPECT_EQ(st.clipped_away, 1u);
}

TEST(Visible, NonFiniteVerticesAreStillErrors) {
  PipelineOptions opt;
  opt.visible = PixelRect{0, 0, 320, 240};
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                     -std::numeric_limits<double>::infinity()}) {
    // Off-screen apart from the bad value: the check comes first, whatever the rectangle says.
    Triangle t{screen(-50, 10), screen(-10, 10), screen(-30, 40)};
    t[1].pos.y = bad;
    std::vector<DeviceTriangle> out;
    EXPECT_FALSE(process_triangle(t, opt, out));
    EXPECT_TRUE(out.empty());
    ScreenVertex s[3];
    s[0].x = -50, s[1].x = bad, s[2].x = -30, s[2].y = 40;
    EXPECT_FALSE(process_screen_triangle({s[0], s[1], s[2]}, opt, out));
  }
}

}  // namespace
}  // namespace gpubridge::geometry
