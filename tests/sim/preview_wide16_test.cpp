// The plain preview kernel's instances (backends/sim/src/preview_plain.cpp): the AVX-512 one draws
// the wide rows of untextured draws in chunks of 16 pixels (span16, preview_plain_kernel.inc; since
// sim-rzrow to the span's end, its last chunk masked to the last 1-15 pixels), the AVX2 and baseline
// ones in chunks of 8. Every instance must store the same bytes and count the
// same pixels on this CPU: random wide boxes (spans of 1 to about 200 pixels, so whole chunks of
// 16, tails of 1 to 15 and rows shorter than 16), every depth function with and without the Z
// write, blend OFF and ALPHA, random stored depths (lanes pass and fail within a chunk) and
// stored depths every lane passes or fails against.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "preview_box_edges.hpp"
#include "preview_plain.hpp"
#include "setup.hpp"

namespace gpubridge::sim::test {
namespace {

constexpr unsigned kW = 256, kH = 40;  // the buffers' size in pixels
constexpr std::size_t kPitch = std::size_t{kW} * 4;

struct Case {
  PreviewPlain p;
  int y0 = 0;  // the box origin's row
  FixedPlanes planes;
  std::vector<std::uint8_t> color, depth;
};

Case random_case(std::mt19937& rng) {
  Case c;
  random_buffer(rng, c.color, kW, kH);
  c.depth.resize(kPitch * kH);
  const unsigned fill = rng() % 4;  // 0, 1: random depths; 2: the farthest (LESS passes); 3: 0
  for (std::size_t k = 0; k < c.depth.size(); ++k)
    c.depth[k] = fill < 2 ? static_cast<std::uint8_t>(rng()) : fill == 2 ? 0xFF : 0;
  // A triangle with its box inside the buffer: wide (up to the whole row) or thin.
  int x[3], y[3];
  random_points(rng, x, y, kW, kH);
  const PreviewBox b = place_triangle(x, y, c.p, c.planes, kW);
  c.y0 = b.by0;
  PreviewPlain& p = c.p;
  random_planes(rng, c.planes);
  p.ky0 = static_cast<int>(rng() % 3);
  p.rows = std::max(0, std::min(b.by1, static_cast<int>(kH)) - b.by0 - p.ky0);
  random_depth_test(rng, p, 4);
  p.zmask = rng() % 2 ? 0xFFFFFFu : 0xFFFF00u;
  p.blend = rng() % 3 == 0 ? protocol::BlendMode::Alpha : protocol::BlendMode::Off;
  return c;
}

PreviewCounts draw(ShadeRoutine shade, const Case& c, std::vector<std::uint8_t>& color, std::vector<std::uint8_t>& depth) {
  return draw_case(shade, c, kW, color, depth);
}

TEST(SimPreviewWide16, SameBytesAndCountsAsTheEightLaneInstances) {
  const ShadeRoutine wide = shade_instance(2);
  if (!wide) GTEST_SKIP() << "no AVX-512 on this CPU";
  ASSERT_NE(shade_instance(0), nullptr);
  std::mt19937 rng(2411);
  std::uint64_t passed = 0, chunks16 = 0;
  for (int n = 0; n < 3000; ++n) {
    const Case c = random_case(rng);
    std::vector<std::uint8_t> color16, depth16;
    const PreviewCounts got = draw(wide, c, color16, depth16);
    for (unsigned isa = 0; isa < 2; ++isa) {
      const ShadeRoutine ref = shade_instance(isa);
      if (!ref) continue;
      std::vector<std::uint8_t> color8, depth8;
      const PreviewCounts want = draw(ref, c, color8, depth8);
      ASSERT_TRUE(same_draw(got, want, color16, color8, depth16, depth8)) << "case " << n << " isa " << isa;
    }
    passed += got.passed;
    if (c.p.width >= 16) ++chunks16;
  }
  // The cases drew something, with boxes wide enough for chunks of 16 among them.
  EXPECT_GT(passed, 0u);
  EXPECT_GT(chunks16, 1000u);
}

}  // namespace
}  // namespace gpubridge::sim::test
