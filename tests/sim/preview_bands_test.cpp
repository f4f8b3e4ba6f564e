// The plain preview kernel's wide rows in one call over rows it does not draw (issue 24,
// sim-preview12: shade_wide steps its walk and colour anchor over another worker's bands instead
// of a call per band). At N threads a worker draws every N-th 16-row band of a triangle
// (PreviewPlain::band_step); that one call must store the same bytes and count the same pixels as
// a call per own band (band_step 0, rows of that band only: what the kernel did before), for
// every instance this CPU runs, on tall boxes (thin slivers crossing many bands, and wide ones),
// every depth function, blend OFF and ALPHA, random stored depths.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "preview_box_edges.hpp"
#include "preview_plain.hpp"
#include "setup.hpp"

namespace gpubridge::sim::test {
namespace {

constexpr unsigned kW = 192, kH = 200;  // the buffers' size in pixels
constexpr int kBand = 16;

struct Case {
  PreviewPlain p;
  FixedPlanes planes;
  std::vector<std::uint8_t> color, depth;
};

Case random_case(std::mt19937& rng) {
  Case c;
  random_buffer(rng, c.color, kW, kH);
  random_buffer(rng, c.depth, kW, kH);
  int x[3], y[3];
  if (rng() % 2) {  // a sliver from a point out to a far one, as the fan's: short spans, many bands
    x[0] = static_cast<int>(rng() % (16 * kW));
    y[0] = static_cast<int>(rng() % (16 * kH));
    x[1] = static_cast<int>(rng() % (16 * kW));
    y[1] = static_cast<int>(rng() % (16 * kH));
    const int spread = 8 + static_cast<int>(rng() % 64);
    x[2] = std::clamp(x[1] + static_cast<int>(rng() % (2 * spread)) - spread, 0, 16 * static_cast<int>(kW) - 1);
    y[2] = std::clamp(y[1] + static_cast<int>(rng() % (2 * spread)) - spread, 0, 16 * static_cast<int>(kH) - 1);
  } else {
    random_points(rng, x, y, kW, kH);
  }
  const PreviewBox b = place_triangle(x, y, c.p, c.planes, kW);
  PreviewPlain& p = c.p;
  random_planes(rng, c.planes, /*small_cdy=*/true);
  random_depth_test(rng, p, 3);
  p.blend = rng() % 3 == 0 ? protocol::BlendMode::Alpha : protocol::BlendMode::Off;
  // The rows a worker got: from a random row of the box to its end (as rasterize_bands passed
  // them, the first row of the worker's first band, before sim-gap's one run of bands per worker).
  const int rows = std::min(b.by1, static_cast<int>(kH)) - b.by0;
  p.ky0 = rows > 0 ? static_cast<int>(rng() % static_cast<unsigned>(std::min(rows, 20))) : 0;
  p.rows = std::max(0, rows - p.ky0);
  return c;
}

// Rows [ky0, ky0 + rows) of the case's box drawn by `shade` with band_step `step` (0: all of them).
PreviewCounts draw_rows(ShadeRoutine shade, const Case& c, int ky0, int rows, int step, std::vector<std::uint8_t>& color,
                        std::vector<std::uint8_t>& depth) {
  PreviewPlain p = c.p;
  p.ky0 = ky0;
  p.rows = rows;
  p.band_step = step;
  aim_at_rows(p, ky0, color.data(), depth.data(), kW);
  return shade(p);
}

TEST(SimPreviewBands, OneCallOverAWorkersBandsIsACallPerBand) {
  std::mt19937 rng(2412);
  std::uint64_t passed = 0, many_bands = 0, thin = 0;
  for (int n = 0; n < 1500; ++n) {
    const Case c = random_case(rng);
    if (c.p.rows <= 0 || c.p.width <= 8) continue;
    const int step = 2 + static_cast<int>(rng() % 2);
    for (unsigned isa = 0; isa < 3; ++isa) {
      const ShadeRoutine shade = shade_instance(isa);
      if (!shade) continue;
      std::vector<std::uint8_t> color1 = c.color, depth1 = c.depth;
      const PreviewCounts got = draw_rows(shade, c, c.p.ky0, c.p.rows, step, color1, depth1);
      // The same worker's bands one call each: the first band from ky0, then every step-th.
      std::vector<std::uint8_t> color2 = c.color, depth2 = c.depth;
      PreviewCounts want;
      int bands = 0;
      for (int r = 0; r < c.p.rows;) {
        const int y = c.p.y + c.p.ky0 + r;
        const int end = std::min(c.p.rows, (y | (kBand - 1)) + 1 - c.p.y - c.p.ky0);
        const PreviewCounts d = draw_rows(shade, c, c.p.ky0 + r, end - r, 0, color2, depth2);
        want.scanned += d.scanned;
        want.covered += d.covered;
        want.passed += d.passed;
        ++bands;
        r = end + (step - 1) * kBand;
      }
      ASSERT_TRUE(same_draw(got, want, color1, color2, depth1, depth2)) << "case " << n << " isa " << isa;
      if (isa == 0) {
        passed += got.passed;
        if (bands >= 3) ++many_bands;
        if (c.p.width > 8 && got.covered < static_cast<std::uint64_t>(4 * c.p.rows)) ++thin;
      }
    }
  }
  // Something was drawn, by workers with three or more bands of a box, thin slivers among them.
  EXPECT_GT(passed, 0u);
  EXPECT_GT(many_bands, 200u);
  EXPECT_GT(thin, 100u);
}

}  // namespace
}  // namespace gpubridge::sim::test
