// The minimal GL yardstick of `gpubridge bench accuracy` (bench/llvmpipe/minimal_gl.c, issue 17),
// run the way the bench runs it (run_minimal_gl: the bench's vertex file, LP_NUM_THREADS) on Mesa
// llvmpipe through EGL surfaceless, with no display.
#include <gtest/gtest.h>

#include <algorithm>

#include "gpubridge/bench/scenes.hpp"
#include "minimal_gl_runner.hpp"

namespace gpubridge::bench {
namespace {

using geometry::ScreenVertex;

// A full-screen quad (two triangles) of one colour at depth z.
void add_quad(Scene& s, double z, geometry::Vec4 colour) {
  const double w = s.width, h = s.height;
  const ScreenVertex a{0, 0, z, 1, colour, {}}, b{w, 0, z, 1, colour, {}}, c{w, h, z, 1, colour, {}}, d{0, h, z, 1, colour, {}};
  for (const auto& tri : {std::array{a, b, c}, std::array{a, c, d}}) {
    auto t = geometry::convert_triangle(tri, {});
    ASSERT_TRUE(t) << t.error().message;
    s.triangles.push_back(*t);
  }
}

Scene quads(bool near_first) {
  Scene s;
  s.name = "quads";
  s.width = 64;
  s.height = 48;
  s.state.z_test = s.state.z_write = true;
  s.state.z_func = protocol::DepthFunc::Less;
  // Red at z = 0.25 and white at z = 0.75: with depth LESS red covers every pixel in either order.
  if (near_first) add_quad(s, 0.25, {1, 0, 0, 1});
  add_quad(s, 0.75, {1, 1, 1, 1});
  if (!near_first) add_quad(s, 0.25, {1, 0, 0, 1});
  return s;
}

constexpr unsigned long long kRedFrameSum = 64ull * 48 * (255 + 255);  // R and A of every pixel

TEST(MinimalGl, DrawsTheBenchVerticesWithDepthLessAtOneAndTwoThreads) {
  for (unsigned lp_threads : {0u, 2u})
    for (bool near_first : {true, false}) {
      const Scene s = quads(near_first);
      ASSERT_TRUE(minimal_gl_draws(s));
      auto run = run_minimal_gl(GPUBRIDGE_MINIMAL_GL, s, lp_threads, {.runs = 2, .min_seconds = 0});
      ASSERT_TRUE(run) << run.error().message;
      EXPECT_EQ(run->pixel_sum, kRedFrameSum) << "LP_NUM_THREADS=" << lp_threads << ", near quad first: " << near_first;
      EXPECT_GT(run->best_seconds, 0.0);
    }
}

TEST(MinimalGl, TimesFramesUntilTheWindowIsFull) {
  const Scene s = quads(true);
  auto counted = run_minimal_gl(GPUBRIDGE_MINIMAL_GL, s, 0, {.runs = 3, .min_seconds = 0});
  ASSERT_TRUE(counted) << counted.error().message;
  EXPECT_EQ(counted->frames, 3u);  // no window: the count alone
  // Two quads of 64 x 48 take well under 50 ms a frame, so a 150 ms window needs more than 3 frames.
  auto windowed = run_minimal_gl(GPUBRIDGE_MINIMAL_GL, s, 0, {.runs = 3, .min_seconds = 0.15});
  ASSERT_TRUE(windowed) << windowed.error().message;
  EXPECT_GT(windowed->frames, 3u);
  EXPECT_LE(windowed->frames, 2001u);
  EXPECT_EQ(windowed->pixel_sum, kRedFrameSum);
}

TEST(MinimalGl, DrawsExactlyTheDepthLessGouraudScenes) {
  auto scenes = make_scenes(200);
  ASSERT_TRUE(scenes) << scenes.error().message;
  std::vector<std::string> drawn;
  for (const auto& s : *scenes)
    if (minimal_gl_draws(s)) drawn.push_back(s.name);
  EXPECT_EQ(drawn, (std::vector<std::string>{"tri10-front", "tri1k-front", "tri50k-front", "tri10-random",
                                             "tri1k-random", "tri50k-random"}));
}

TEST(MinimalGl, AMissingProgramIsAClearError) {
  auto run = run_minimal_gl("/nonexistent/minimal_gl", quads(true), 0, {.runs = 1});
  ASSERT_FALSE(run);
  EXPECT_NE(run.error().message.find("minimal GL program"), std::string::npos) << run.error().message;
}

}  // namespace
}  // namespace gpubridge::bench
