// End to end through the USB board path (issue 5): a real gpubridged on an emulated board
// (`--backend emulated:PROFILE`: the bridge chip's byte-exact model + the simulator behind the
// same libusb/hidapi transport interface the real driver uses) plays a trace; the frame read back
// through the emulated bridge equals `gpubridge render` of the same trace pixel for pixel.
#include <gtest/gtest.h>

#include <future>
#include <nlohmann/json.hpp>

#include "bridge_chips.hpp"
#include "daemon_process.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/common/image.hpp"

namespace gpubridge::test {
namespace {

using namespace std::chrono_literals;

// The profile to run: the shipped one when it reads frames back, else a copy with
// "scanout": "readback" (CH341A/MCP2210 ship CRC-only scanout because they are slow; the copy
// keeps the chip, wiring and clock, so the same driver and chip model carry the pixels).
std::string readback_profile(const std::string& name, const fs::path& dir) {
  const fs::path shipped = fs::path(GPUBRIDGE_BOARDS_DIR) / (name + ".json");
  std::ifstream in(shipped);
  auto j = nlohmann::json::parse(in);
  if (j.value("scanout", "") == "readback") return name;
  j["scanout"] = "readback";
  const fs::path copy = dir / (name + ".json");
  std::ofstream(copy) << j.dump(2);
  return copy.string();
}

class DaemonBoard : public ::testing::TestWithParam<std::string> {};

TEST_P(DaemonBoard, PlayedTraceReadBackThroughEmulatedBridgeEqualsInProcessRender) {
  const auto dir = make_temp_dir("brd-" + GetParam());
  const auto socket = (dir / "d.sock").string();
  const std::string trace = std::string(GPUBRIDGE_TEST_DATA) + "/board_triangles.trace";
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", "unix:" + socket, "--backend", "emulated:" + readback_profile(GetParam(), dir),
                            "--no-fallback", "--log-level", "warn"}))
      << daemon.error();

  auto watcher = client::Client::connect("unix:" + socket, 2000ms);
  ASSERT_TRUE(watcher);
  ASSERT_TRUE(watcher->handshake("watcher", "", 2000ms));
  // The daemon really runs the board path for this chip (not the simulator).
  {
    auto s = watcher->status(2000ms);
    ASSERT_TRUE(s);
    const auto status = nlohmann::json::parse(*s);
    EXPECT_NE(status.dump().find("\"board\":\"" + GetParam() + "\""), std::string::npos) << status.dump();
  }

  auto shot = std::async(std::launch::async, [&] {
    return run_process({GPUBRIDGE_CLI_PATH, "screenshot", "--out", (dir / "shot.png").string(), "--connect", "unix:" + socket});
  });
  // Draw only once the screenshot client is subscribed.
  bool subscribed = false;
  for (int i = 0; i < 500 && !subscribed; ++i) {
    auto s = watcher->status(1000ms);
    ASSERT_TRUE(s);
    const auto status = nlohmann::json::parse(*s);
    for (const auto& cl : status["clients"]) subscribed = subscribed || cl["subscribed"].get<bool>();
    if (!subscribed) std::this_thread::sleep_for(10ms);
  }
  if (!subscribed) {
    const auto r = shot.get();
    FAIL() << "screenshot never subscribed; it exited " << r.exit_code << ": " << r.err << r.out;
  }
  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", trace, "--connect", "unix:" + socket});
  ASSERT_EQ(play.exit_code, 0) << play.err << play.out;
  const auto s = shot.get();
  ASSERT_EQ(s.exit_code, 0) << s.err << s.out;
  const auto render = run_process({GPUBRIDGE_CLI_PATH, "render", trace, "--out", (dir / "ref.png").string()});
  ASSERT_EQ(render.exit_code, 0) << render.err;

  auto got = load_png(dir / "shot.png");
  auto want = load_png(dir / "ref.png");
  ASSERT_TRUE(got) << got.error().message;
  ASSERT_TRUE(want) << want.error().message;
  ASSERT_EQ(got->width, 64u);
  ASSERT_EQ(got->height, 48u);
  // The triangles are there (not just the clear colour) ...
  EXPECT_NE(std::vector<std::uint8_t>(got->pixel(30, 30), got->pixel(30, 30) + 4),
            std::vector<std::uint8_t>(got->pixel(63, 47), got->pixel(63, 47) + 4));
  // ... and the frame that crossed the emulated bridge equals the in-process render exactly.
  EXPECT_TRUE(got->rgba == want->rgba);
  EXPECT_EQ(daemon.terminate(), 0);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

INSTANTIATE_TEST_SUITE_P(FourBridgeChips, DaemonBoard, test::kFourBridgeChips, test::chip_test_name);

// Errors name the problem and what to do.
// A CRC-only board (the shipped ch341a-generic profile) counts its swaps but must not hand
// subscribers a frame without pixels dressed up as a blank image.
TEST(DaemonBoardCrcOnly, SwapsAreCountedButNoBlankFrameIsSent) {
  const auto dir = make_temp_dir("brd-crc");
  const auto socket = (dir / "d.sock").string();
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", "unix:" + socket, "--backend", "emulated:ch341a-generic", "--no-fallback",
                            "--log-level", "warn"}))
      << daemon.error();
  auto sub = client::Client::connect("unix:" + socket, 2000ms);
  ASSERT_TRUE(sub);
  ASSERT_TRUE(sub->handshake("sub", "", 2000ms));
  // RGBA8888: the daemon converts, so a pixel-less frame would arrive as a well-formed blank image.
  ASSERT_TRUE(sub->subscribe(protocol::FrameFormat::RGBA8888, 0, 2000ms));
  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", std::string(GPUBRIDGE_TEST_DATA) + "/board_triangles.trace",
                                 "--connect", "unix:" + socket});
  ASSERT_EQ(play.exit_code, 0) << play.err << play.out;
  EXPECT_FALSE(sub->next_frame(500ms)) << "a CRC-only board produced a frame with pixels";
  auto s = sub->status(2000ms);
  ASSERT_TRUE(s);
  EXPECT_GE(nlohmann::json::parse(*s)["frames"]["count"].get<int>(), 1) << "the swap was not counted";
}

TEST(DaemonBoardErrors, UnknownProfileListsTheKnownOnes) {
  const auto dir = make_temp_dir("brd-unknown");
  const auto r = run_process({GPUBRIDGED_PATH, "--listen", "unix:" + (dir / "d.sock").string(), "--backend", "no-such-board"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("no-such-board"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ft232h-generic"), std::string::npos) << r.err;
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace gpubridge::test
