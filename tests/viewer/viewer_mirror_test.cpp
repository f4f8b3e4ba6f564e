// gpubridge-view against a mirror-mode gpubridged (`--backend emulated:icebreaker --mirror`: the
// board's driver over an emulated FT2232H, with the simulator fed the same commands), under a
// private Xvfb:
// - `--source diff --frames 1 --screenshot` saves the diff picture: every pixel the documented
//   dimmed grey of `gpubridge render`'s pixel (board and simulator agree), and the window shows it;
// - the D key switches a running viewer from the board to the diff picture of the same swap;
// - `--source sim` against a daemon without --mirror fails with one line naming --mirror.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <thread>

#include <nlohmann/json.hpp>

#include "gpubridge/common/image.hpp"
#include "daemon_fixture.hpp"
#include "process.hpp"
#include "xvfb_suite.hpp"

namespace gpubridge::viewer::test {
namespace {

using namespace std::chrono_literals;

const std::string kViewer = GPUBRIDGE_VIEW_PATH;
const std::string kCli = GPUBRIDGE_CLI_PATH;

// 160x120 RGB565 (fits the iCEBreaker profile's 320x240 / 128 KiB): a clear and one flat triangle.
const char* kTrace =
    "FB_FORMAT WIDTH=160 HEIGHT=120 FORMAT=RGB565\n"
    "SCISSOR X0=0 Y0=0 X1=160 Y1=120\n"
    "FB_DRAW ADDR=0\n"
    "CLEAR_COLOR R=20 G=90 B=200 A=255\n"
    "CLEAR\n"
    "PRIM TYPE=LIST\n"
    "COLOR R=255 G=200 B=0 A=255\n"
    "VERTEX X=10 Y=10 Z=0\n"
    "VERTEX X=150 Y=20 Z=0\n"
    "VERTEX X=80 Y=110 Z=0\n"
    "FB_DISPLAY ADDR=0\n";

// docs/protocol.md, SUBSCRIBE source 2: an equal pixel becomes grey (77 R + 150 G + 29 B) / 256 / 2.
std::uint8_t dimmed_grey(const std::uint8_t* rgba) {
  return static_cast<std::uint8_t>(((77u * rgba[0] + 150u * rgba[1] + 29u * rgba[2]) >> 8) / 2);
}

class ViewerMirror : public XvfbSuite {
 protected:
  void SetUp() override {
    XvfbSuite::SetUp();
    if (no_display()) return;
    socket_ = "unix:" + (dir_.path() / "g.sock").string();
    trace_ = (dir_.path() / "tri.txt").string();
    std::ofstream(trace_) << kTrace;
  }

  std::unique_ptr<BackgroundProcess> start_daemon(std::vector<std::string> extra) {
    extra.push_back("--no-fallback");
    return test::start_daemon(socket_, extra, dir_.path(), "daemon");
  }

  ::testing::AssertionResult wait_subscribed(BackgroundProcess& viewer) { return test::wait_subscribed(viewer, socket_); }

  // Once the viewer has subscribed: plays the trace, waits for the viewer to exit 0 and reads
  // its JSON summary.
  void play_until_done(BackgroundProcess& viewer, nlohmann::json& summary) {
    ASSERT_TRUE(wait_subscribed(viewer));
    const auto play = run_process({kCli, "play", trace_, "--connect", socket_});
    ASSERT_EQ(play.exit_code, 0) << play.out << play.err;
    const auto code = viewer.wait_exit(60s);
    ASSERT_TRUE(code.has_value()) << "viewer did not finish: " << viewer.log();
    ASSERT_EQ(*code, 0) << viewer.log();
    summary = nlohmann::json::parse(viewer.output());
  }

  std::unique_ptr<BackgroundProcess> start_viewer(std::vector<std::string> args) {
    args.insert(args.begin(), {kViewer, "--connect", socket_, "--offscreen", "--json", "--timeout", "60"});
    return std::make_unique<BackgroundProcess>(args, std::vector<std::string>{"DISPLAY=" + xvfb_->display()},
                                               dir_.path(), "viewer");
  }

  Image rendered() {
    const auto png = (dir_.path() / "render.png").string();
    const auto r = run_process({kCli, "render", trace_, "-o", png});
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    auto img = load_png(png);
    EXPECT_TRUE(img.ok());
    return img.ok() ? *img : Image{};
  }

  // Every pixel of `diff` is the dimmed grey of `want`'s pixel (no magenta: board == simulator).
  static ::testing::AssertionResult all_dimmed_grey(const Image& diff, const Image& want) {
    if (diff.width != want.width || diff.height != want.height)
      return ::testing::AssertionFailure() << "size " << diff.width << "x" << diff.height;
    for (unsigned y = 0; y < diff.height; ++y)
      for (unsigned x = 0; x < diff.width; ++x) {
        const std::uint8_t g = dimmed_grey(want.pixel(x, y));
        const std::uint8_t* d = diff.pixel(x, y);
        if (d[0] != g || d[1] != g || d[2] != g || d[3] != 255)
          return ::testing::AssertionFailure() << "pixel " << x << "," << y << " is " << int(d[0]) << "," << int(d[1])
                                               << "," << int(d[2]) << "," << int(d[3]) << ", want grey " << int(g);
      }
    return ::testing::AssertionSuccess();
  }

  TempDir dir_;
  std::string socket_, trace_;
};

TEST_F(ViewerMirror, SourceDiffSavesTheDiffPictureAndTheWindowShowsIt) {
  auto daemon = start_daemon({"--backend", "emulated:icebreaker", "--mirror"});
  const auto shot = (dir_.path() / "diff.png").string(), grab = (dir_.path() / "grab.png").string();
  auto viewer = start_viewer({"--source", "diff", "--frames", "1", "--screenshot", shot, "--grab-window", grab,
                              "--size", "640x480", "--scale", "integer", "--no-overlay"});
  nlohmann::json summary;
  ASSERT_NO_FATAL_FAILURE(play_until_done(*viewer, summary));
  EXPECT_EQ(summary["source"], "diff") << summary.dump();
  EXPECT_EQ(summary["format"], "RGBA8888") << summary.dump();
  EXPECT_EQ(summary["crc_ok"], true);

  const Image want = rendered();
  ASSERT_EQ(want.width, 160u);
  auto diff = load_png(shot);
  ASSERT_TRUE(diff.ok());
  EXPECT_TRUE(all_dimmed_grey(*diff, want));
  // Not a flat picture: the triangle is there in grey.
  EXPECT_NE(diff->pixel(80, 40)[0], diff->pixel(2, 2)[0]);

  // The window shows the diff at factor 4 (640x480 / 160x120).
  auto window = load_png(grab);
  ASSERT_TRUE(window.ok());
  ASSERT_EQ(window->width, 640u);
  for (unsigned y = 0; y < 120; y += 7)
    for (unsigned x = 0; x < 160; x += 5) {
      const std::uint8_t* got = window->pixel(4 * x + 2, 4 * y + 1);
      ASSERT_TRUE(std::equal(got, got + 3, diff->pixel(x, y))) << "window pixel of frame pixel " << x << "," << y;
    }
}

TEST_F(ViewerMirror, KeyDSwitchesFromTheBoardToTheDiffOfTheSameSwap) {
  auto daemon = start_daemon({"--backend", "emulated:icebreaker", "--mirror"});
  const auto shot = (dir_.path() / "second.png").string();
  // Frame 1 is the board picture; D is typed when it arrives; frame 2 is the diff of the same
  // swap (the daemon re-sends the newest swap in the new picture), with no further play.
  auto viewer = start_viewer({"--frames", "2", "--screenshot", shot, "--press", "D"});
  nlohmann::json summary;
  ASSERT_NO_FATAL_FAILURE(play_until_done(*viewer, summary));
  EXPECT_EQ(summary["source"], "diff") << summary.dump();
  auto diff = load_png(shot);
  ASSERT_TRUE(diff.ok());
  EXPECT_TRUE(all_dimmed_grey(*diff, rendered()));
}

TEST_F(ViewerMirror, SimulatorPictureWithoutMirrorModeFailsWithOneLine) {
  auto daemon = start_daemon({"--backend", "sim"});
  const auto r = run_process({kViewer, "--connect", socket_, "--source", "sim", "--frames", "1", "--screenshot",
                              (dir_.path() / "x.png").string(), "--offscreen", "--timeout", "20"},
                             {"DISPLAY=" + xvfb_->display()});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("--mirror"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("UNAVAILABLE"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

}  // namespace
}  // namespace gpubridge::viewer::test
