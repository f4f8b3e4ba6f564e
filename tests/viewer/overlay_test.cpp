// Overlay text (font, panel geometry, wording), the rate meter and the window title.
#include <gtest/gtest.h>

#include "gpubridge/viewer/font8x8.hpp"
#include "gpubridge/viewer/overlay.hpp"
#include "gpubridge/viewer/rate_meter.hpp"
#include "gpubridge/viewer/text_panel.hpp"

namespace gpubridge::viewer {
namespace {

bool lit(const Image& img, unsigned x, unsigned y) { return img.pixel(x, y)[0] == 255; }

TEST(Font, CoversPrintableAsciiAndMapsTheRestToQuestionMark) {
  EXPECT_EQ(glyph(' '), (std::array<std::uint8_t, 8>{}));
  for (char c = '!'; c <= '~'; ++c) {
    const auto& g = glyph(c);
    bool any = false;
    for (auto row : g) any = any || row != 0;
    EXPECT_TRUE(any) << "glyph '" << c << "' is blank";
  }
  EXPECT_EQ(glyph('\n'), glyph('?'));
  EXPECT_EQ(glyph(static_cast<char>(200)), glyph('?'));
  // Distinct characters look distinct (catches a shifted table).
  for (char a = '!'; a <= '~'; ++a)
    for (char b = static_cast<char>(a + 1); b <= '~' && b > a; ++b) EXPECT_NE(glyph(a), glyph(b)) << a << b;
}

TEST(TextPanel, PlacesGlyphPixelsWhereTheFontSays) {
  const Image img = render_text_panel({"I", "-"}, 2);
  // 1 column, 2 rows: (2*4 + 8) * 2 = 32 wide, (2*4 + 16) * 2 = 48 high.
  ASSERT_EQ(img.width, 32u);
  ASSERT_EQ(img.height, 48u);
  for (unsigned row = 0; row < 2; ++row) {
    const auto& g = glyph(row == 0 ? 'I' : '-');
    for (unsigned gy = 0; gy < 8; ++gy) {
      for (unsigned gx = 0; gx < 8; ++gx) {
        const bool on = (g[gy] >> gx) & 1;
        for (unsigned s = 0; s < 4; ++s) {  // all four pixels of the 2x2 cell
          const unsigned x = (4 + gx) * 2 + s % 2, y = (4 + 8 * row + gy) * 2 + s / 2;
          ASSERT_EQ(lit(img, x, y), on) << "row " << row << " glyph pixel " << gx << "," << gy;
          ASSERT_EQ(img.pixel(x, y)[3], on ? 255 : kPanelAlpha);
        }
      }
    }
  }
  EXPECT_FALSE(lit(img, 0, 0));  // padding is background
  EXPECT_EQ(img.pixel(0, 0)[3], kPanelAlpha);
}

TEST(TextPanel, BoundsItsSize) {
  EXPECT_EQ(render_text_panel({}, 1).width, 0u);
  EXPECT_EQ(render_text_panel({""}, 1).width, 0u);
  const Image wide = render_text_panel({std::string(100000, 'x')}, 1);
  EXPECT_EQ(wide.width, 2 * kPanelPadding + 8 * kMaxPanelLineChars);
  const Image tall = render_text_panel(std::vector<std::string>(1000, "a"), 1);
  EXPECT_EQ(tall.height, 2 * kPanelPadding + 8 * kMaxPanelLines);
  const Image huge_scale = render_text_panel({"a"}, 1000);
  EXPECT_EQ(huge_scale.width, (2 * kPanelPadding + 8) * kMaxPanelScale);
}

TEST(RateMeter, MeasuresEventsPerSecondOverTheWindow) {
  RateMeter m;
  EXPECT_EQ(m.rate(), 0.0);
  for (int i = 0; i <= 30; ++i) m.sample(static_cast<std::uint64_t>(i) * 100'000'000u, static_cast<std::uint64_t>(i) * 6);
  EXPECT_NEAR(m.rate(), 60.0, 1e-9);  // 6 events per 100 ms
  m.sample(3'100'000'000u, 180);      // stalled for 100 ms
  EXPECT_LT(m.rate(), 60.0);
  m.sample(3'000'000'000u, 5);  // went backwards (new source): starts over
  EXPECT_EQ(m.rate(), 0.0);
}

TEST(Overlay, SaysWhatIsShownAndHowFast) {
  ViewState v;
  v.status.state = SourceStatus::State::Streaming;
  v.status.address = "unix:/tmp/g.sock";
  v.status.backend = "sim";
  v.status.board = "ulx3s";
  v.frame = ShownFrame{42, 640, 480, protocol::PixelFormat::RGB565, true};
  v.fps_received = 59.94;
  v.fps_drawn = 30;
  v.latency_ms = 12.25;
  v.scale = ScaleMode::Integer;
  v.flipped = true;
  std::string all;
  for (const auto& line : overlay_lines(v)) all += line + "\n";
  for (const char* expected : {"unix:/tmp/g.sock  sim/ulx3s", "frame 42  640x480 RGB565", "received 59.9",
                               "drawn 30.0", "latency swap->display 12.2", "scale integer", "flipped"}) {
    EXPECT_NE(all.find(expected), std::string::npos) << expected << " not in\n" << all;
  }
  EXPECT_EQ(all.find("CRC MISMATCH"), std::string::npos);
  v.frame->crc_ok = false;
  v.latency_ms.reset();
  all.clear();
  for (const auto& line : overlay_lines(v)) all += line + "\n";
  EXPECT_NE(all.find("CRC MISMATCH"), std::string::npos);
  EXPECT_NE(all.find("latency swap->display n/a"), std::string::npos);
  EXPECT_EQ(window_title(v), "gpubridge-view - unix:/tmp/g.sock - sim/ulx3s - 640x480 RGB565");
}

TEST(Overlay, ShowsTheWaitingState) {
  SourceStatus s;
  s.state = SourceStatus::State::Waiting;
  s.address = "tcp:127.0.0.1:7420";
  s.message = "connection refused";
  EXPECT_EQ(status_line(s), "waiting for gpubridged at tcp:127.0.0.1:7420 (connection refused)");
  ViewState v;
  v.status = s;
  EXPECT_NE(window_title(v).find("[waiting]"), std::string::npos);
  s.state = SourceStatus::State::Streaming;
  EXPECT_EQ(status_line(s), "");
}

TEST(Overlay, HelpListsEveryKey) {
  std::string all;
  for (const auto& line : help_lines()) all += line + "\n";
  for (const char* key : {" S ", " F ", " I ", "1 2 3", " P ", " O ", " ? ", "Q Esc"})
    EXPECT_NE(all.find(key), std::string::npos) << key;
}

}  // namespace
}  // namespace gpubridge::viewer
