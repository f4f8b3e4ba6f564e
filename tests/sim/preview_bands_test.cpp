// The plain preview kernel's wide rows in one call over a worker's run of 16-row bands. Since
// sim-gap a worker draws one run of whole bands of a triangle in one call (draw_preview_plain with
// its rows); that call must store the same bytes and count the same pixels as a call per band
// (rows of that band only: how the renderer split the rows before), for every instance this CPU
// runs, on tall boxes (thin slivers crossing many bands, and wide ones), every depth function,
// blend OFF and ALPHA, random stored depths. (Until sim-pprune this tested one call over every
// N-th band of a worker, PreviewPlain::band_step, against a call per own band; that path is gone.)
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
  int y0 = 0;  // the box origin's row
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
  c.y0 = b.by0;
  PreviewPlain& p = c.p;
  random_planes(rng, c.planes, /*small_cdy=*/true);
  random_depth_test(rng, p, 3);
  p.blend = rng() % 3 == 0 ? protocol::BlendMode::Alpha : protocol::BlendMode::Off;
  // The rows a worker got: from a random row of the box to its end (a run's first row is the first
  // row of the worker's first band, anywhere in the box).
  const int rows = std::min(b.by1, static_cast<int>(kH)) - b.by0;
  p.ky0 = rows > 0 ? static_cast<int>(rng() % static_cast<unsigned>(std::min(rows, 20))) : 0;
  p.rows = std::max(0, rows - p.ky0);
  return c;
}

// Rows [ky0, ky0 + rows) of the case's box drawn by `shade`.
PreviewCounts draw_rows(ShadeRoutine shade, const Case& c, int ky0, int rows, std::vector<std::uint8_t>& color,
                        std::vector<std::uint8_t>& depth) {
  PreviewPlain p = c.p;
  p.ky0 = ky0;
  p.rows = rows;
  aim_at_rows(p, c.y0, ky0, color.data(), depth.data(), kW);
  return shade(p);
}

TEST(SimPreviewBands, OneCallOverAWorkersRunIsACallPerBand) {
  std::mt19937 rng(2412);
  std::uint64_t passed = 0, many_bands = 0, thin = 0;
  for (int n = 0; n < 1500; ++n) {
    const Case c = random_case(rng);
    if (c.p.rows <= 0 || c.p.width <= 8) continue;
    for (unsigned isa = 0; isa < 3; ++isa) {
      const ShadeRoutine shade = shade_instance(isa);
      if (!shade) continue;
      std::vector<std::uint8_t> color1 = c.color, depth1 = c.depth;
      const PreviewCounts got = draw_rows(shade, c, c.p.ky0, c.p.rows, color1, depth1);
      // The same rows one call per band: the first band from ky0, then each next one.
      std::vector<std::uint8_t> color2 = c.color, depth2 = c.depth;
      PreviewCounts want;
      int bands = 0;
      for (int r = 0; r < c.p.rows;) {
        const int y = c.y0 + c.p.ky0 + r;
        const int end = std::min(c.p.rows, (y | (kBand - 1)) + 1 - c.y0 - c.p.ky0);
        const PreviewCounts d = draw_rows(shade, c, c.p.ky0 + r, end - r, color2, depth2);
        want.scanned += d.scanned;
        want.covered += d.covered;
        want.passed += d.passed;
        ++bands;
        r = end;
      }
      ASSERT_TRUE(same_draw(got, want, color1, color2, depth1, depth2)) << "case " << n << " isa " << isa;
      if (isa == 0) {
        passed += got.passed;
        if (bands >= 3) ++many_bands;
        if (c.p.width > 8 && got.covered < static_cast<std::uint64_t>(4 * c.p.rows)) ++thin;
      }
    }
  }
  // Something was drawn, by runs of three or more bands of a box, thin slivers among them.
  EXPECT_GT(passed, 0u);
  EXPECT_GT(many_bands, 200u);
  EXPECT_GT(thin, 100u);
}

}  // namespace
}  // namespace gpubridge::sim::test
