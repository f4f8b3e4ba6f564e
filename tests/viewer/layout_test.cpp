// Where the frame is drawn: aspect ratio, whole-number scaling, fixed zooms, degenerate sizes.
#include <gtest/gtest.h>

#include <cmath>

#include "gpubridge/viewer/layout.hpp"

namespace gpubridge::viewer {
namespace {

TEST(Layout, FitKeepsAspectRatioAndCentres) {
  // 4:3 frame in a 16:9 window: height-limited, pillarboxed.
  EXPECT_EQ(frame_rect(1920, 1080, 640, 480, ScaleMode::Fit), (Rect{240, 0, 1440, 1080}));
  // 4:3 frame in a tall window: width-limited, letterboxed.
  EXPECT_EQ(frame_rect(800, 1000, 640, 480, ScaleMode::Fit), (Rect{0, 200, 800, 600}));
  // Same aspect: fills exactly.
  EXPECT_EQ(frame_rect(320, 240, 640, 480, ScaleMode::Fit), (Rect{0, 0, 320, 240}));
}

TEST(Layout, FitAspectErrorIsBelowOnePixel) {
  for (unsigned fw : {1u, 3u, 7u, 320u, 1024u}) {
    for (unsigned fh : {1u, 5u, 240u, 1000u}) {
      const Rect r = frame_rect(997, 613, fw, fh, ScaleMode::Fit);
      ASSERT_GT(r.width, 0);
      ASSERT_GT(r.height, 0);
      ASSERT_LE(r.width, 997);
      ASSERT_LE(r.height, 613);
      EXPECT_TRUE(r.width == 997 || r.height == 613) << fw << "x" << fh;
      // The other side is within one pixel of the exact aspect-preserving length.
      const double exact_h = static_cast<double>(r.width) * fh / fw;
      const double exact_w = static_cast<double>(r.height) * fw / fh;
      EXPECT_TRUE(std::abs(exact_h - r.height) <= 1.0 || std::abs(exact_w - r.width) <= 1.0) << fw << "x" << fh;
    }
  }
}

TEST(Layout, IntegerUsesTheLargestWholeFactorThatFits) {
  EXPECT_EQ(frame_rect(1000, 1000, 320, 240, ScaleMode::Integer), (Rect{20, 140, 960, 720}));
  EXPECT_EQ(frame_rect(640, 480, 160, 120, ScaleMode::Integer), (Rect{0, 0, 640, 480}));
  // Window smaller than the frame: factor 1, centred and cropped.
  EXPECT_EQ(frame_rect(100, 100, 320, 240, ScaleMode::Integer), (Rect{-110, -70, 320, 240}));
}

TEST(Layout, ZoomsAreFixedFactors) {
  EXPECT_EQ(frame_rect(1000, 800, 100, 50, ScaleMode::Zoom1), (Rect{450, 375, 100, 50}));
  EXPECT_EQ(frame_rect(1000, 800, 100, 50, ScaleMode::Zoom2), (Rect{400, 350, 200, 100}));
  EXPECT_EQ(frame_rect(1000, 800, 100, 50, ScaleMode::Zoom3), (Rect{350, 325, 300, 150}));
}

TEST(Layout, DegenerateSizesGiveAnEmptyRect) {
  EXPECT_EQ(frame_rect(0, 480, 320, 240, ScaleMode::Fit), Rect{});
  EXPECT_EQ(frame_rect(640, -5, 320, 240, ScaleMode::Integer), Rect{});
  EXPECT_EQ(frame_rect(640, 480, 0, 240, ScaleMode::Zoom2), Rect{});
  // Extreme aspect ratios still give at least one pixel.
  const Rect r = frame_rect(10, 10, 1024, 1, ScaleMode::Fit);
  EXPECT_EQ(r.width, 10);
  EXPECT_EQ(r.height, 1);
}

TEST(Layout, InitialWindowSizeIsAWholeMultipleThatFits) {
  EXPECT_EQ(initial_window_size(320, 240, 1700, 1000).width, 1280);
  EXPECT_EQ(initial_window_size(320, 240, 1700, 1000).height, 960);
  EXPECT_EQ(initial_window_size(1024, 1024, 800, 600).width, 800);  // too big: clamped to the screen
  EXPECT_EQ(initial_window_size(1024, 1024, 800, 600).height, 600);
  EXPECT_EQ(initial_window_size(0, 0, 800, 600).width, 640);
}

}  // namespace
}  // namespace gpubridge::viewer
