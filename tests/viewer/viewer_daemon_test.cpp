// gpubridge-view against a real gpubridged on the simulator, under a private Xvfb: a trace played
// with `gpubridge play` reaches the viewer, whose screenshot equals `gpubridge render` of the same
// trace pixel for pixel and whose window shows it; and the viewer survives a daemon restart.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <set>
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
const std::string kDaemon = GPUBRIDGED_PATH;
const std::string kCli = GPUBRIDGE_CLI_PATH;

// 160x120 RGB565: a clear and one flat triangle, then a swap. Colours differ per call so two
// plays are told apart.
std::string triangle_trace(int clear_r, int clear_g, int clear_b) {
  return "FB_FORMAT WIDTH=160 HEIGHT=120 FORMAT=RGB565\n"
         "SCISSOR X0=0 Y0=0 X1=160 Y1=120\n"
         "FB_DRAW ADDR=0\n"
         "CLEAR_COLOR R=" + std::to_string(clear_r) + " G=" + std::to_string(clear_g) +
         " B=" + std::to_string(clear_b) + " A=255\n"
         "CLEAR\n"
         "PRIM TYPE=LIST\n"
         "COLOR R=255 G=40 B=0 A=255\n"
         "VERTEX X=10 Y=10 Z=0\n"
         "VERTEX X=150 Y=20 Z=0\n"
         "VERTEX X=80 Y=110 Z=0\n"
         "FB_DISPLAY ADDR=0\n";
}

class ViewerDaemon : public XvfbSuite {
 protected:
  void SetUp() override {
    XvfbSuite::SetUp();
    if (no_display()) return;
    socket_ = "unix:" + (dir_.path() / "g.sock").string();
  }

  std::string write_trace(const std::string& name, const std::string& text) {
    const auto path = (dir_.path() / name).string();
    std::ofstream(path) << text;
    return path;
  }

  std::unique_ptr<BackgroundProcess> start_daemon(const std::string& name) {
    return test::start_daemon(socket_, {"--backend", "sim"}, dir_.path(), name);
  }

  ::testing::AssertionResult wait_subscribed(BackgroundProcess& viewer) { return test::wait_subscribed(viewer, socket_); }

  void play(const std::string& trace) {
    const auto r = run_process({kCli, "play", trace, "--connect", socket_});
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  }

  Image render(const std::string& trace, const std::string& png) {
    const auto r = run_process({kCli, "render", trace, "-o", png});
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    auto img = load_png(png);
    EXPECT_TRUE(img.ok());
    return img.ok() ? *img : Image{};
  }

  std::unique_ptr<BackgroundProcess> start_viewer(std::vector<std::string> args, const std::string& name) {
    args.insert(args.begin(), {kViewer, "--connect", socket_, "--offscreen", "--json", "--timeout", "60"});
    return std::make_unique<BackgroundProcess>(args, std::vector<std::string>{"DISPLAY=" + xvfb_->display()},
                                               dir_.path(), name);
  }

  TempDir dir_;
  std::string socket_;
};

TEST_F(ViewerDaemon, PlayedTraceReachesTheViewerPixelExactly) {
  auto daemon = start_daemon("daemon");
  const auto shot = (dir_.path() / "view.png").string(), grab = (dir_.path() / "grab.png").string();
  auto viewer = start_viewer({"--frames", "1", "--screenshot", shot, "--grab-window", grab, "--size", "640x480",
                              "--scale", "integer", "--no-overlay"},
                             "viewer");
  ASSERT_TRUE(wait_subscribed(*viewer));
  const auto trace = write_trace("tri.txt", triangle_trace(20, 40, 200));
  play(trace);
  const auto code = viewer->wait_exit(30s);
  ASSERT_TRUE(code.has_value()) << "viewer did not finish: " << viewer->log();
  ASSERT_EQ(*code, 0) << viewer->log();
  const auto summary = nlohmann::json::parse(viewer->output());
  EXPECT_EQ(summary["crc_ok"], true);
  EXPECT_EQ(summary["format"], "RGB565");

  // The viewer's screenshot against the simulator rendering the same trace in-process.
  const auto rendered_path = (dir_.path() / "render.png").string();
  const Image rendered = render(trace, rendered_path);
  const auto cmp = run_process({kCli, "compare", rendered_path, shot});
  EXPECT_EQ(cmp.exit_code, 0) << cmp.out << cmp.err;
  auto seen = load_png(shot);
  ASSERT_TRUE(seen.ok());
  EXPECT_TRUE(*seen == rendered);

  // The window shows it at factor 4 (640x480 / 160x120): sample every frame pixel's block.
  auto window = load_png(grab);
  ASSERT_TRUE(window.ok());
  ASSERT_EQ(window->width, 640u);
  std::set<std::uint32_t> colors;
  for (unsigned y = 0; y < 120; ++y) {
    for (unsigned x = 0; x < 160; ++x) {
      const std::uint8_t* want = rendered.pixel(x, y);
      const std::uint8_t* got = window->pixel(4 * x + 2, 4 * y + 1);
      ASSERT_TRUE(want[0] == got[0] && want[1] == got[1] && want[2] == got[2]) << "frame pixel " << x << "," << y;
      colors.insert((got[0] << 16) | (got[1] << 8) | got[2]);
    }
  }
  EXPECT_GE(colors.size(), 2u) << "the window shows a flat colour: the triangle is missing";
}

TEST_F(ViewerDaemon, SurvivesADaemonRestart) {
  auto daemon = start_daemon("daemon1");
  const auto shot = (dir_.path() / "second.png").string();
  // Frame 2 is the first frame after the restart.
  auto viewer = start_viewer({"--frames", "2", "--screenshot", shot, "--log-level", "info"}, "viewer");
  ASSERT_TRUE(wait_subscribed(*viewer));
  play(write_trace("a.txt", triangle_trace(0, 200, 0)));

  daemon->kill_and_wait(SIGTERM);
  std::this_thread::sleep_for(300ms);
  EXPECT_TRUE(viewer->running()) << "the viewer exited when the daemon went away: " << viewer->log();
  daemon = start_daemon("daemon2");
  ASSERT_TRUE(wait_subscribed(*viewer));
  const auto trace_b = write_trace("b.txt", triangle_trace(200, 0, 200));
  play(trace_b);
  const auto code = viewer->wait_exit(30s);
  ASSERT_TRUE(code.has_value()) << "viewer did not finish: " << viewer->log();
  ASSERT_EQ(*code, 0) << viewer->log();
  EXPECT_NE(viewer->log().find("lost"), std::string::npos) << viewer->log();
  auto seen = load_png(shot);
  ASSERT_TRUE(seen.ok());
  EXPECT_TRUE(*seen == render(trace_b, (dir_.path() / "b.png").string()));
}

TEST_F(ViewerDaemon, RefusedTokenGivesOneLineAndExitThree) {
  // A TCP daemon that requires a token; the viewer presents the wrong one.
  const std::string tcp = "tcp:127.0.0.1:" + std::to_string(20000 + (getpid() % 20000));
  BackgroundProcess daemon({kDaemon, "--backend", "sim", "--listen", tcp, "--token", "right-token", "--foreground"},
                           {}, dir_.path(), "tcp-daemon");
  bool up = false;
  for (int i = 0; i < 200 && !up; ++i) {
    up = run_process({kCli, "status", "--connect", tcp, "--token", "right-token"}).exit_code == 0;
    if (!up) std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(up) << daemon.log();
  const auto r = run_process({kViewer, "--connect", tcp, "--token", "wrong-token", "--frames", "1", "--screenshot",
                              (dir_.path() / "x.png").string(), "--offscreen"},
                             {"DISPLAY=" + xvfb_->display()});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("token"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

}  // namespace
}  // namespace gpubridge::viewer::test
