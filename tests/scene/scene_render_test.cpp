// The example scenes end to end through the simulator: scene file → geometry pipeline → command
// stream → SimBackend → scanned-out frame. Expected pixels are derived here from the scene's
// geometry and docs/protocol.md formulas, independently of the code under test.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <variant>

#include "gpubridge/scene/scene.hpp"
#include "gpubridge/sim/sim_backend.hpp"

namespace gpubridge::scene {
namespace {

struct Rendered {
  Image image;
  std::uint16_t device_errors = 0;
};

Rendered render(const std::string& file) {
  auto built = load_scene(std::string(GPUBRIDGE_EXAMPLE_SCENES) + "/" + file);
  EXPECT_TRUE(built) << built.error().message;
  auto sim = sim::SimBackend::create();
  EXPECT_TRUE(sim);
  std::shared_ptr<const backends::ScanoutFrame> last;
  (*sim)->set_scanout_callback([&](std::shared_ptr<const backends::ScanoutFrame> f) { last = std::move(f); });
  for (const auto& c : built->stream.commands) {
    if (const auto* f = std::get_if<protocol::FramesCmd>(&c.command)) {
      EXPECT_TRUE((*sim)->write_frames(f->view()));
    } else if (const auto* u = std::get_if<protocol::UploadCmd>(&c.command)) {
      EXPECT_TRUE((*sim)->upload(u->address, u->data));
    }
  }
  EXPECT_TRUE((*sim)->flush());
  Rendered r;
  r.device_errors = (*sim)->device().errors();
  EXPECT_TRUE(last) << "no frame was scanned out";
  if (last) r.image = image_from_device(last->format, last->width, last->height, last->pixels);
  return r;
}

std::array<int, 4> at(const Image& img, unsigned x, unsigned y) {
  const auto* p = img.pixel(x, y);
  return {p[0], p[1], p[2], p[3]};
}

int div255(int x) { return (x + 128 + ((x + 128) >> 8)) >> 8; }  // docs/protocol.md section 10.5

TEST(SceneRender, GouraudTriangle) {
  const auto r = render("gouraud-triangle.json");
  EXPECT_EQ(r.device_errors, 0);
  ASSERT_EQ(r.image.width, 160u);
  // Outside: the clear colour round(0.05·255) = 13, round(0.2·255) = 51.
  EXPECT_EQ(at(r.image, 2, 2), (std::array<int, 4>{13, 13, 51, 255}));
  // Near each vertex the colour is dominated by that vertex's channel.
  const auto top = at(r.image, 80, 14), right = at(r.image, 144, 108), left = at(r.image, 16, 108);
  EXPECT_GT(top[0], 200);
  EXPECT_LT(top[1], 40);
  EXPECT_GT(right[1], 200);
  EXPECT_GT(left[2], 200);
  // At the centroid (80, 76.67) each channel is about a third (barycentric weights ≈ 1/3).
  const auto mid = at(r.image, 80, 76);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mid[c], 85, 6) << c;
}

TEST(SceneRender, DepthIntersectionResolvedPerPixel) {
  const auto r = render("depth-intersection.json");
  EXPECT_EQ(r.device_errors, 0);
  // Left part: the orange triangle is nearer (z 0.2 at x = 10) than the blue one (0.8 at x = 10).
  EXPECT_EQ(at(r.image, 25, 60), (std::array<int, 4>{255, 128, 0, 255}));
  // Right part: the blue one is nearer.
  EXPECT_EQ(at(r.image, 135, 60), (std::array<int, 4>{0, 153, 255, 255}));
}

// Solves the homography screen (x, y) → texture (u, v) from the floor quad's four corners.
std::array<double, 8> homography(const std::array<std::array<double, 4>, 4>& pts) {
  double a[8][9] = {};
  for (int i = 0; i < 4; ++i) {
    const double x = pts[i][0], y = pts[i][1], u = pts[i][2], v = pts[i][3];
    const double r0[9] = {x, y, 1, 0, 0, 0, -u * x, -u * y, u};
    const double r1[9] = {0, 0, 0, x, y, 1, -v * x, -v * y, v};
    for (int k = 0; k < 9; ++k) a[2 * i][k] = r0[k], a[2 * i + 1][k] = r1[k];
  }
  for (int c = 0; c < 8; ++c) {  // Gauss-Jordan with partial pivoting
    int piv = c;
    for (int r = c + 1; r < 8; ++r)
      if (std::fabs(a[r][c]) > std::fabs(a[piv][c])) piv = r;
    for (int k = 0; k < 9; ++k) std::swap(a[c][k], a[piv][k]);
    for (int r = 0; r < 8; ++r) {
      if (r == c) continue;
      const double f = a[r][c] / a[c][c];
      for (int k = 0; k < 9; ++k) a[r][k] -= f * a[c][k];
    }
  }
  std::array<double, 8> h{};
  for (int i = 0; i < 8; ++i) h[i] = a[i][8] / a[i][i];
  return h;
}

TEST(SceneRender, TexturedFloorIsPerspectiveCorrect) {
  const auto r = render("textured-floor.json");
  EXPECT_EQ(r.device_errors, 0);
  // The floor corners as written by make_scenes.py: (x, y, u, v).
  const auto h = homography({{{-40, 119, 0, 0}, {200, 119, 8, 0}, {200 - 120 * (15.0 / 16), 30, 8, 8},
                              {-40 + 120 * (15.0 / 16), 30, 0, 8}}});
  // RGB565 texels (230 → 28 → 231; 40 → 5 → 41, 60 → 7 → 57, green 40 → 10 → 40) modulated by white.
  const std::array<int, 4> light{231, 231, 231, 255}, dark{41, 40, 57, 255};
  int checked = 0;
  for (unsigned y = 45; y < 118; y += 3)
    for (unsigned x = 0; x < 160; x += 3) {
      const double sx = x + 0.5, sy = y + 0.5;
      const double d = h[6] * sx + h[7] * sy + 1;
      const double u = (h[0] * sx + h[1] * sy + h[2]) / d, v = (h[3] * sx + h[4] * sy + h[5]) / d;
      if (u < 0.05 || u > 7.95) continue;  // outside the floor or at its edge
      const double cu = u * 2, cv = v * 2;  // checker cell coordinates (8 texels of 16)
      auto near_edge = [](double c) { return std::fabs(c - std::round(c)) < 0.08; };
      if (near_edge(cu) || near_edge(cv)) continue;
      const bool is_light = ((static_cast<int>(std::floor(cu)) + static_cast<int>(std::floor(cv))) & 1) == 0;
      EXPECT_EQ(at(r.image, x, y), is_light ? light : dark) << "pixel " << x << "," << y << " u=" << u << " v=" << v;
      ++checked;
    }
  EXPECT_GT(checked, 500);
}

TEST(SceneRender, AlphaBlendMatchesTheBlendFormula) {
  const auto r = render("alpha-blend.json");
  EXPECT_EQ(r.device_errors, 0);
  const int alpha = 128, grey = 128;  // round(0.5·255)
  // A pixel inside the red triangle only (apex region at (60, 20)).
  const auto p = at(r.image, 60, 22);
  EXPECT_EQ(p[0], div255(255 * alpha + grey * (255 - alpha)));
  EXPECT_EQ(p[1], div255(0 * alpha + grey * (255 - alpha)));
  // At (62, 72) red and then blue cover the pixel (green's left edge is at x = 64.2 there):
  // blue blended over the red result.
  const auto q = at(r.image, 62, 72);
  const int red_r = div255(255 * alpha + grey * (255 - alpha)), red_gb = div255(grey * (255 - alpha));
  EXPECT_EQ(q[0], div255(red_r * (255 - alpha)));
  EXPECT_EQ(q[1], div255(red_gb * (255 - alpha)));
  EXPECT_EQ(q[2], div255(255 * alpha + red_gb * (255 - alpha)));
}

TEST(SceneRender, DitheredGradientAveragesToTheTrueColour) {
  const auto r = render("dither-rgba2222.json");
  EXPECT_EQ(r.device_errors, 0);
  for (unsigned y = 0; y < r.image.height; ++y)
    for (unsigned x = 0; x < r.image.width; ++x)
      for (int c = 0; c < 4; ++c) ASSERT_EQ(at(r.image, x, y)[c] % 85, 0);  // 2-bit values expanded
  // Over 4x4 blocks (one Bayer tile) the mean red follows the gradient through the dither of
  // docs/protocol.md section 11.5. In the upper-right triangle red is the plane through
  // (0,0,0), (160,0,1), (160,120,1): red = x/160 at the pixel centre.
  static constexpr int kBayer[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};
  for (unsigned bx : {40u, 96u, 140u}) {
    double sum = 0, expect = 0;
    for (unsigned y = 4; y < 8; ++y)
      for (unsigned x = bx; x < bx + 4; ++x) {
        sum += at(r.image, x, y)[0];
        const int v = static_cast<int>(std::lround((x + 0.5) / 160 * 255));
        expect += 85 * (std::min(255, v + ((kBayer[y & 3][x & 3] << 6) >> 4)) >> 6);
      }
    // An interpolation difference of ±1 in v moves at most one pixel of the 16 by one step (85).
    EXPECT_NEAR(sum / 16, expect / 16, 85.0 / 16 + 1e-9) << "block at x = " << bx;
  }
}

TEST(SceneRender, EveryExampleSceneRendersWithoutDeviceErrors) {
  for (const char* f : {"gouraud-triangle.json", "depth-intersection.json", "textured-floor.json", "alpha-blend.json",
                        "dither-rgba2222.json"}) {
    const auto r = render(f);
    EXPECT_EQ(r.device_errors, 0) << f;
    EXPECT_GT(r.image.width, 0u) << f;
  }
}

}  // namespace
}  // namespace gpubridge::scene
