// gpubridge-view end to end under a private Xvfb (Mesa software OpenGL), fed by its built-in
// test pattern: the screenshot is the frame's own pixels, the window grab shows the frame at the
// right place and scale, flip works, the overlay is drawn, and the no-display path still saves.
// Expected pixels come from the test pattern's documented formula, computed here independently.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include <nlohmann/json.hpp>

#include "gpubridge/common/image.hpp"
#include "process.hpp"
#include "xvfb_suite.hpp"

namespace gpubridge::viewer::test {
namespace {

const std::string kViewer = GPUBRIDGE_VIEW_PATH;

struct Rgb { int r, g, b; };

// The test pattern (docs/viewer.md): r = (x + n) mod 256, g = y mod 256, b = 255 on odd 8x8
// checker squares, stored in `format` by truncation, shown by bit replication.
Rgb expected_pixel(unsigned x, unsigned y, unsigned n, const std::string& format) {
  const int r = static_cast<int>((x + n) % 256), g = static_cast<int>(y % 256);
  const int b = ((x / 8 + y / 8) % 2) ? 255 : 0;
  if (format == "RGB565") {
    const int r5 = r >> 3, g6 = g >> 2, b5 = b >> 3;
    return {(r5 << 3) | (r5 >> 2), (g6 << 2) | (g6 >> 4), (b5 << 3) | (b5 >> 2)};
  }
  if (format == "RGBA2222") return {(r >> 6) * 85, (g >> 6) * 85, (b >> 6) * 85};
  return {r, g, b};
}

::testing::AssertionResult pixel_is(const Image& img, unsigned x, unsigned y, Rgb want) {
  const std::uint8_t* p = img.pixel(x, y);
  if (p[0] == want.r && p[1] == want.g && p[2] == want.b) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "pixel (" << x << "," << y << ") is " << int{p[0]} << "," << int{p[1]}
                                       << "," << int{p[2]} << " expected " << want.r << "," << want.g << ","
                                       << want.b;
}

class ViewerGl : public XvfbSuite {
 protected:
  ProcessResult view(std::vector<std::string> args) {
    args.insert(args.begin(), kViewer);
    return run_process(args, {"DISPLAY=" + xvfb_->display(), "WAYLAND_DISPLAY="});
  }
  static nlohmann::json summary(const ProcessResult& r) { return nlohmann::json::parse(r.out); }

  TempDir dir_;
};

TEST_F(ViewerGl, ScreenshotIsExactlyTheFramesPixels) {
  for (const std::string format : {"RGBA8888", "RGB565", "RGBA2222"}) {
    const auto shot = (dir_.path() / (format + ".png")).string();
    const auto r = view({"--test-source", "96x64:" + format, "--frames", "3", "--screenshot", shot, "--json",
                         "--offscreen"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = summary(r);
    EXPECT_EQ(j["frames_taken"], 3);
    EXPECT_EQ(j["format"], format);
    EXPECT_EQ(j["crc_ok"], true);
    const unsigned n = j["frame"];
    auto img = load_png(shot);
    ASSERT_TRUE(img.ok()) << img.error().message;
    ASSERT_EQ(img->width, 96u);
    ASSERT_EQ(img->height, 64u);
    for (unsigned y = 0; y < 64; ++y)
      for (unsigned x = 0; x < 96; ++x) ASSERT_TRUE(pixel_is(*img, x, y, expected_pixel(x, y, n, format))) << format;
  }
}

TEST_F(ViewerGl, WindowGrabShowsTheFrameAtAWholeNumberScale) {
  const auto grab = (dir_.path() / "grab.png").string();
  const auto r = view({"--test-source", "160x120:rgb565", "--frames", "2", "--grab-window", grab, "--size", "640x480",
                       "--scale", "integer", "--no-overlay", "--offscreen", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const unsigned n = summary(r)["frame"];
  auto img = load_png(grab);
  ASSERT_TRUE(img.ok()) << img.error().message;
  ASSERT_EQ(img->width, 640u);
  ASSERT_EQ(img->height, 480u);
  // Factor 4, filling the window: every 4x4 block is one frame pixel (check all four corners).
  for (unsigned y = 0; y < 120; ++y) {
    for (unsigned x = 0; x < 160; ++x) {
      const Rgb want = expected_pixel(x, y, n, "RGB565");
      ASSERT_TRUE(pixel_is(*img, 4 * x, 4 * y, want));
      ASSERT_TRUE(pixel_is(*img, 4 * x + 3, 4 * y + 3, want));
    }
  }
}

TEST_F(ViewerGl, FlipShowsTheBottomRowAtTheTop) {
  const auto grab = (dir_.path() / "flip.png").string();
  const auto r = view({"--test-source", "64x48", "--frames", "1", "--grab-window", grab, "--size", "128x96",
                       "--scale", "integer", "--no-overlay", "--flip", "--offscreen", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const unsigned n = summary(r)["frame"];
  auto img = load_png(grab);
  ASSERT_TRUE(img.ok());
  for (unsigned y = 0; y < 48; ++y)
    for (unsigned x = 0; x < 64; ++x)
      ASSERT_TRUE(pixel_is(*img, 2 * x + 1, 2 * (47 - y) + 1, expected_pixel(x, y, n, "RGBA8888")));
}

TEST_F(ViewerGl, FitKeepsTheAspectRatioWithBarsAroundTheFrame) {
  const auto grab = (dir_.path() / "fit.png").string();
  // 4:3 frame in a square window: 320x240 drawn at 320 wide, 240 high, starting at y = 40.
  const auto r = view({"--test-source", "160x120", "--frames", "1", "--grab-window", grab, "--size", "320x320",
                       "--no-overlay", "--offscreen", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const unsigned n = summary(r)["frame"];
  auto img = load_png(grab);
  ASSERT_TRUE(img.ok());
  ASSERT_EQ(img->height, 320u);
  for (unsigned y = 0; y < 120; ++y)
    for (unsigned x = 0; x < 160; ++x)
      ASSERT_TRUE(pixel_is(*img, 2 * x + 1, 40 + 2 * y + 1, expected_pixel(x, y, n, "RGBA8888")));
  // The bars are the (dark grey) background, not frame pixels.
  for (unsigned x = 0; x < 320; x += 7) {
    const std::uint8_t* top = img->pixel(x, 10);
    const std::uint8_t* bottom = img->pixel(x, 300);
    EXPECT_LT(top[0], 40);
    EXPECT_EQ(top[0], bottom[0]);
    EXPECT_EQ(top[1], bottom[1]);
  }
}

TEST_F(ViewerGl, OverlayTextIsDrawnOverTheFrame) {
  const auto grab = (dir_.path() / "overlay.png").string();
  const auto r = view({"--test-source", "160x120", "--frames", "2", "--grab-window", grab, "--size", "640x480",
                       "--offscreen", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto img = load_png(grab);
  ASSERT_TRUE(img.ok());
  // The pattern never has white in the top-left (g = y < 32 there): white pixels are glyphs.
  unsigned white = 0;
  for (unsigned y = 0; y < 60; ++y)
    for (unsigned x = 0; x < 200; ++x) {
      const std::uint8_t* p = img->pixel(x, y);
      white += p[0] == 255 && p[1] == 255 && p[2] == 255;
    }
  EXPECT_GT(white, 200u);
}

TEST_F(ViewerGl, WithoutAnyDisplayOffscreenStillSavesTheFrame) {
  const auto shot = (dir_.path() / "nodisplay.png").string();
  const auto r = run_process({kViewer, "--test-source", "32x16:rgba2222", "--frames", "2", "--screenshot", shot,
                              "--offscreen", "--json"},
                             {"DISPLAY=", "WAYLAND_DISPLAY="});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const unsigned n = summary(r)["frame"];
  auto img = load_png(shot);
  ASSERT_TRUE(img.ok());
  for (unsigned y = 0; y < 16; ++y)
    for (unsigned x = 0; x < 32; ++x) ASSERT_TRUE(pixel_is(*img, x, y, expected_pixel(x, y, n, "RGBA2222")));

  // A window (or a window grab) needs a display: one clear line, non-zero exit.
  const auto windowed = run_process({kViewer, "--test-source", "32x16"}, {"DISPLAY=", "WAYLAND_DISPLAY="});
  EXPECT_EQ(windowed.exit_code, 1);
  EXPECT_NE(windowed.err.find("no display"), std::string::npos) << windowed.err;
  const auto grab = run_process({kViewer, "--test-source", "32x16", "--offscreen", "--grab-window", "x.png"},
                                {"DISPLAY=", "WAYLAND_DISPLAY="});
  EXPECT_EQ(grab.exit_code, 1);
  EXPECT_NE(grab.err.find("no display"), std::string::npos) << grab.err;
}

TEST_F(ViewerGl, UsageErrorsExitWithTwoAndSayWhy) {
  const auto r = view({"--frames", "0", "--screenshot", "x.png"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--frames"), std::string::npos) << r.err;
  const auto t = view({"--test-source", "5000x1", "--frames", "1", "--screenshot", "x.png", "--offscreen"});
  EXPECT_EQ(t.exit_code, 2);
  EXPECT_NE(t.err.find("5000x1"), std::string::npos) << t.err;
}

TEST_F(ViewerGl, KeysFlipZoomAndSaveTheFrame) {
  // Keys typed when the first frame arrives (hidden --press): F flips, 2 zooms 2:1 (centred),
  // S saves the frame's own pixels into --screenshot-dir.
  const auto grab = (dir_.path() / "keys.png").string();
  const auto r = view({"--test-source", "64x48:rgb565", "--frames", "1", "--grab-window", grab, "--size", "256x192",
                       "--no-overlay", "--offscreen", "--json", "--press", "F2S", "--screenshot-dir",
                       dir_.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const unsigned n = summary(r)["frame"];
  auto img = load_png(grab);
  ASSERT_TRUE(img.ok());
  for (unsigned y = 0; y < 48; ++y)
    for (unsigned x = 0; x < 64; ++x)
      ASSERT_TRUE(pixel_is(*img, 64 + 2 * x, 48 + 2 * (47 - y) + 1, expected_pixel(x, y, n, "RGB565")));
  EXPECT_LT(img->pixel(10, 10)[0], 40);  // outside the 2:1 frame: background
  char name[64];
  std::snprintf(name, sizeof name, "gpubridge-frame-%06u.png", n);
  auto saved = load_png(dir_.path() / name);
  ASSERT_TRUE(saved.ok()) << saved.error().message;
  ASSERT_EQ(saved->width, 64u);
  for (unsigned y = 0; y < 48; ++y)
    for (unsigned x = 0; x < 64; ++x) ASSERT_TRUE(pixel_is(*saved, x, y, expected_pixel(x, y, n, "RGB565")));

  // I: largest whole factor (3 in 200x200: 192x144 at 4,28); the same zoom key twice: back to fit.
  const auto r2 = view({"--test-source", "64x48", "--frames", "1", "--grab-window", grab, "--size", "200x200",
                        "--no-overlay", "--offscreen", "--json", "--press", "I"});
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  const unsigned n2 = summary(r2)["frame"];
  img = load_png(grab);
  ASSERT_TRUE(img.ok());
  for (unsigned y = 0; y < 48; ++y)
    for (unsigned x = 0; x < 64; ++x)
      ASSERT_TRUE(pixel_is(*img, 4 + 3 * x + 1, 28 + 3 * y + 1, expected_pixel(x, y, n2, "RGBA8888")));
  const auto r3 = view({"--test-source", "64x48", "--frames", "1", "--grab-window", grab, "--size", "256x192",
                        "--no-overlay", "--offscreen", "--json", "--press", "33"});
  ASSERT_EQ(r3.exit_code, 0) << r3.err;
  const unsigned n3 = summary(r3)["frame"];
  img = load_png(grab);
  ASSERT_TRUE(img.ok());
  for (unsigned y = 0; y < 48; ++y)
    for (unsigned x = 0; x < 64; ++x)
      ASSERT_TRUE(pixel_is(*img, 4 * x + 2, 4 * y + 2, expected_pixel(x, y, n3, "RGBA8888")));  // fit = 4x here
}

TEST_F(ViewerGl, UnreachableDaemonGivesOneLineAndExitThree) {
  const auto shot = (dir_.path() / "never.png").string();
  const auto r = view({"--connect", "unix:" + (dir_.path() / "no-daemon.sock").string(), "--frames", "1",
                       "--screenshot", shot, "--offscreen"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("no-daemon.sock"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(shot));
}

}  // namespace
}  // namespace gpubridge::viewer::test
