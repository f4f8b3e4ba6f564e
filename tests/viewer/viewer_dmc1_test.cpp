// gpubridge-view showing the DMC-1 example client live, under a private Xvfb, as the README runs it:
// `gpubridged --backend dmc1`, `gpubridge-view` and `gpubridge-dmc1-demo stream`, all on the default
// socket (XDG_RUNTIME_DIR is the test's own directory). The viewer's frame is the committed golden of
// the same frame of the level, bit for bit, and its window shows it.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "daemon_fixture.hpp"
#include "gpubridge/common/image.hpp"
#include "process.hpp"
#include "xvfb_suite.hpp"

namespace gpubridge::viewer::test {
namespace {

using namespace std::chrono_literals;

class ViewerDmc1 : public XvfbSuite {
 protected:
  void SetUp() override {
    XvfbSuite::SetUp();
    if (no_display()) return;
    std::filesystem::create_directories(dir_.path() / "run");
    env_ = {"XDG_RUNTIME_DIR=" + (dir_.path() / "run").string(), "GPUBRIDGE_ADDRESS=", "GPUBRIDGE_TOKEN=",
            "DISPLAY=" + xvfb_->display()};
    socket_ = "unix:" + (dir_.path() / "run" / "gpubridge" / "gpubridge.sock").string();
  }
  TempDir dir_;
  std::vector<std::string> env_;
  std::string socket_;  // where the programs find the daemon by default (for the test's own waits)
};

TEST_F(ViewerDmc1, TheLevelStreamedLiveIsShownAsItsGolden) {
  BackgroundProcess daemon({GPUBRIDGED_PATH, "--backend", "dmc1", "--foreground", "--log-level", "warn"}, env_, dir_.path(),
                           "daemon");
  bool up = false;
  for (int i = 0; i < 200 && !up; ++i) {
    up = run_process({GPUBRIDGE_CLI_PATH, "status"}, env_).exit_code == 0;
    if (!up) std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(up) << daemon.log();
  const auto shot = (dir_.path() / "view.png").string(), grab = (dir_.path() / "grab.png").string();
  BackgroundProcess viewer({GPUBRIDGE_VIEW_PATH, "--offscreen", "--json", "--timeout", "60", "--frames", "1", "--screenshot",
                            shot, "--grab-window", grab, "--size", "640x480", "--scale", "integer", "--no-overlay"},
                           env_, dir_.path(), "viewer");
  ASSERT_TRUE(wait_subscribed(viewer, socket_));
  // A fresh daemon's first frame is the chip's first after reset, which is what the golden shows.
  const auto stream = run_process({GPUBRIDGE_DMC1_DEMO_PATH, "stream", "--first", "12", "--frames", "1"}, env_);
  ASSERT_EQ(stream.exit_code, 0) << stream.out << stream.err;
  const auto code = viewer.wait_exit(30s);
  ASSERT_TRUE(code.has_value()) << "viewer did not finish: " << viewer.log();
  ASSERT_EQ(*code, 0) << viewer.log();
  const auto summary = nlohmann::json::parse(viewer.output());
  EXPECT_EQ(summary["crc_ok"], true);
  EXPECT_EQ(summary["format"], "RGB565");
  EXPECT_EQ(summary["width"], 320);
  EXPECT_EQ(summary["height"], 240);

  auto seen = load_png(shot);
  ASSERT_TRUE(seen.ok()) << seen.error().message;
  auto golden = load_png(std::filesystem::path(GPUBRIDGE_DMC1_GOLDEN_DIR) / "level-12.png");
  ASSERT_TRUE(golden.ok()) << golden.error().message;
  EXPECT_TRUE(*seen == *golden) << "the viewer's frame differs from examples/dmc1/golden/level-12.png";

  // The window shows it at factor 2 (640x480 / 320x240): sample every frame pixel's block.
  auto window = load_png(grab);
  ASSERT_TRUE(window.ok()) << window.error().message;
  ASSERT_EQ(window->width, 640u);
  std::set<std::uint32_t> colors;
  for (unsigned y = 0; y < 240; ++y) {
    for (unsigned x = 0; x < 320; ++x) {
      const std::uint8_t* want = golden->pixel(x, y);
      const std::uint8_t* got = window->pixel(2 * x + 1, 2 * y + 1);
      ASSERT_TRUE(want[0] == got[0] && want[1] == got[1] && want[2] == got[2]) << "frame pixel " << x << "," << y;
      colors.insert((got[0] << 16) | (got[1] << 8) | got[2]);
    }
  }
  EXPECT_GE(colors.size(), 16u) << "the window shows too few colours for the textured level";
}

}  // namespace
}  // namespace gpubridge::viewer::test
