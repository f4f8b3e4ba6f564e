// Board hot-plug end to end (issue 4): a real gpubridged on an emulated FT232H board whose adapter
// is plugged in only while a "presence file" exists (`emulated:PROFILE?presence=PATH`). Removing
// the file is an unplug as libusb reports it (every transfer fails with NO_DEVICE, enumeration finds
// nothing); creating it again is a replug. The driver, the daemon and the clients are the real ones.
#include <gtest/gtest.h>

#include <future>
#include <nlohmann/json.hpp>

#include "bridge_chips.hpp"
#include "client_checks.hpp"
#include "daemon_process.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/common/image.hpp"

namespace gpubridge::test {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

constexpr const char* kBoard = "ft232h-generic";  // ships with "scanout": "readback": frames have pixels
// Short, so the test does not wait long for the probe and re-attach; the default is 1000 ms.
constexpr const char* kIntervalMs = "50";

std::string trace_path(const char* name) { return std::string(GPUBRIDGE_TEST_DATA) + "/" + name; }

void plug(const fs::path& presence) { std::ofstream(presence) << "plugged\n"; }
void unplug(const fs::path& presence) { fs::remove(presence); }



// Plays `trace` with `gpubridge play` while `gpubridge screenshot` waits for the frame, renders the
// same trace in-process with `gpubridge render`, and compares the two pictures pixel for pixel.
void expect_screenshot_equals_render(client::Client& watcher, const std::string& socket, const fs::path& dir,
                                     const std::string& trace, const std::string& tag) {
  const auto shot_png = dir / (tag + "-shot.png");
  const auto ref_png = dir / (tag + "-ref.png");
  auto shot = std::async(std::launch::async, [&] {
    return run_process({GPUBRIDGE_CLI_PATH, "screenshot", "--out", shot_png.string(), "--connect", "unix:" + socket});
  });
  bool subscribed = false;  // draw only once the screenshot client is subscribed
  for (int i = 0; i < 500 && !subscribed; ++i) {
    const auto st = status_of(watcher);  // a named copy: ranging over a temporary's member would dangle
    for (const auto& cl : st["clients"]) subscribed = subscribed || cl["subscribed"].get<bool>();
    if (!subscribed) std::this_thread::sleep_for(10ms);
  }
  if (!subscribed) {
    const auto r = shot.get();
    FAIL() << tag << ": screenshot never subscribed; it exited " << r.exit_code << ": " << r.err << r.out;
  }
  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", trace, "--connect", "unix:" + socket});
  ASSERT_EQ(play.exit_code, 0) << tag << ": " << play.err << play.out;
  const auto s = shot.get();
  ASSERT_EQ(s.exit_code, 0) << tag << ": " << s.err << s.out;
  const auto render = run_process({GPUBRIDGE_CLI_PATH, "render", trace, "--out", ref_png.string()});
  ASSERT_EQ(render.exit_code, 0) << tag << ": " << render.err;
  auto got = load_png(shot_png);
  auto want = load_png(ref_png);
  ASSERT_TRUE(got) << got.error().message;
  ASSERT_TRUE(want) << want.error().message;
  ASSERT_EQ(got->width, want->width) << tag;
  ASSERT_EQ(got->height, want->height) << tag;
  // Not just the clear colour: the centre differs from the corner in both traces.
  const unsigned cx = got->width / 2, cy = got->height * 2 / 3;
  EXPECT_NE(std::vector<std::uint8_t>(got->pixel(cx, cy), got->pixel(cx, cy) + 4),
            std::vector<std::uint8_t>(got->pixel(0, 0), got->pixel(0, 0) + 4))
      << tag;
  EXPECT_TRUE(got->rgba == want->rgba) << tag << ": the daemon's frame differs from gpubridge render";
}

struct HotplugDaemon {
  fs::path dir, presence;
  std::string socket;
  Daemon daemon;

  bool start(const std::string& tag, std::vector<std::string> extra, const std::string& board = kBoard) {
    dir = make_temp_dir(tag);
    presence = dir / "present";
    socket = (dir / "d.sock").string();
    plug(presence);
    std::vector<std::string> args{"--listen", "unix:" + socket, "--backend",
                                  "emulated:" + board + "?presence=" + presence.string(),
                                  "--reattach-interval-ms", kIntervalMs, "--log-level", "warn"};
    args.insert(args.end(), extra.begin(), extra.end());
    return daemon.start(args);
  }
  ~HotplugDaemon() {
    daemon.stop();
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

TEST(DaemonHotplug, UnplugFallsBackToTheSimulatorAndReplugBringsTheBoardBack) {
  HotplugDaemon d;
  ASSERT_TRUE(d.start("hp-fallback", {})) << d.daemon.error();
  auto watcher = client::Client::connect("unix:" + d.socket, 2000ms);
  ASSERT_TRUE(watcher);
  ASSERT_TRUE(watcher->handshake("watcher", "", 2000ms));
  {
    const auto st = status_of(*watcher);
    ASSERT_EQ(st["backend"], "board") << st.dump();
    EXPECT_EQ(st["board"], kBoard);
    EXPECT_EQ(st["hotplug"]["enabled"], true) << st.dump();
    EXPECT_EQ(st["hotplug"]["attached"], true);
    EXPECT_EQ(st["hotplug"]["detaches"], 0);
  }
  // A client draws on the emulated board.
  expect_screenshot_equals_render(*watcher, d.socket, d.dir, trace_path("board_triangles.trace"), "board-before");
  EXPECT_EQ(status_of(*watcher)["backend"], "board");

  // Unplug with no client command in flight: the daemon's presence probe notices it.
  unplug(d.presence);
  const auto gone = wait_event(*watcher, "device_gone", 5000ms);
  ASSERT_TRUE(gone) << "no device_gone event after the unplug";
  EXPECT_EQ((*gone)["fallback"], "sim") << gone->dump();
  // The driver saw libusb's NO_DEVICE status (usb_errors.cpp wording), not some emulator shortcut.
  EXPECT_NE((*gone)["message"].get<std::string>().find("no device (unplugged)"), std::string::npos) << gone->dump();
  {
    const auto st = status_of(*watcher);
    EXPECT_EQ(st["backend"], "sim") << st.dump();
    EXPECT_EQ(st["hotplug"]["attached"], false);
    EXPECT_EQ(st["hotplug"]["detaches"], 1);
    EXPECT_EQ(st["hotplug"]["reattaches"], 0);
    const auto cli = run_process({GPUBRIDGE_CLI_PATH, "status", "--connect", "unix:" + d.socket});
    EXPECT_NE(cli.out.find("hot-plug:  board gone (looking for it), 1 unplug(s), 0 re-attach(es)"), std::string::npos)
        << cli.out << cli.err;
  }
  // The daemon keeps serving, on the simulator: what is drawn now renders exactly as in-process.
  expect_screenshot_equals_render(*watcher, d.socket, d.dir, trace_path("triangle.trace"), "on-fallback");

  // Replug: the board is found again, reset, and replaces the simulator.
  plug(d.presence);
  const auto back = wait_event(*watcher, "device_back", 5000ms);
  ASSERT_TRUE(back) << "no device_back event after the replug";
  EXPECT_EQ((*back)["backend"], "board") << back->dump();
  EXPECT_EQ((*back)["board"], kBoard);
  EXPECT_EQ((*back)["state"], "reset");
  {
    const auto st = status_of(*watcher);
    EXPECT_EQ(st["backend"], "board") << st.dump();
    EXPECT_EQ(st["board"], kBoard);
    EXPECT_EQ(st["bridge"], "FT232H");
    EXPECT_EQ(st["hotplug"]["attached"], true);
    EXPECT_EQ(st["hotplug"]["detaches"], 1);
    EXPECT_EQ(st["hotplug"]["reattaches"], 1);
  }
  // A trace played now crosses the re-attached board's bridge and still equals the reference.
  expect_screenshot_equals_render(*watcher, d.socket, d.dir, trace_path("board_triangles.trace"), "board-after");
  EXPECT_EQ(status_of(*watcher)["backend"], "board");
  EXPECT_EQ(d.daemon.terminate(std::chrono::milliseconds(2000)), 0) << "SIGTERM must exit 0 within 2 s";
}

TEST(DaemonHotplug, WithoutFallbackTheLeaseHolderGetsDeviceGoneAndOthersAreStillServed) {
  HotplugDaemon d;
  ASSERT_TRUE(d.start("hp-nofb", {"--no-fallback"})) << d.daemon.error();
  auto holder = client::Client::connect("unix:" + d.socket, 2000ms);
  ASSERT_TRUE(holder);
  ASSERT_TRUE(holder->handshake("holder", "", 2000ms));
  ASSERT_TRUE(holder->acquire_lease(protocol::LeaseMode::Wait, 2000ms));
  auto draw = [&]() -> Result<void> {
    client::RegisterWriter w(*holder);
    if (auto r = w.write(protocol::Reg::CLEAR_COLOR, 0x11223344); !r) return r;
    if (auto r = w.flush(); !r) return r;
    return holder->fence(2000ms);
  };
  ASSERT_TRUE(draw()) << "drawing on the plugged-in board failed";

  unplug(d.presence);
  const auto r = draw();
  ASSERT_FALSE(r) << "a command on the unplugged board succeeded";
  EXPECT_TRUE(client::is_protocol_error(r.error(), protocol::ErrorCode::DeviceGone)) << r.error().message;

  // Another client is still served: status works and says the board is detached (no fallback).
  auto other = client::Client::connect("unix:" + d.socket, 2000ms);
  ASSERT_TRUE(other);
  ASSERT_TRUE(other->handshake("other", "", 2000ms));
  {
    const auto st = status_of(*other);
    ASSERT_FALSE(st.contains("error")) << st.dump();
    EXPECT_EQ(st["backend"], "board") << st.dump();
    EXPECT_EQ(st["hotplug"]["attached"], false) << st.dump();
    EXPECT_EQ(st["hotplug"]["detaches"], 1);
    EXPECT_EQ(st["lease"]["name"], "holder");
  }
  // The holder was told once, without a fallback.
  const auto gone = wait_event(*holder, "device_gone", 2000ms);
  ASSERT_TRUE(gone);
  EXPECT_FALSE(gone->contains("fallback")) << gone->dump();

  // Replug: the board comes back and the holder, still holding the lease, can draw again.
  plug(d.presence);
  ASSERT_TRUE(wait_event(*other, "device_back", 5000ms)) << "no device_back event after the replug";
  // The FENCE above returned its own DEVICE_GONE; the WRITE_FRAMES before it got one too, which the
  // client keeps and hands out with the next fence (client.hpp: WRITE_FRAMES is fire-and-forget).
  const auto leftover = holder->fence(2000ms);
  ASSERT_FALSE(leftover) << "the WRITE_FRAMES sent to the unplugged board was not answered with an error";
  EXPECT_TRUE(client::is_protocol_error(leftover.error(), protocol::ErrorCode::DeviceGone)) << leftover.error().message;
  const auto again = draw();
  EXPECT_TRUE(again) << "drawing on the re-attached board failed: " << again.error().message;
  const auto st = status_of(*other);
  EXPECT_EQ(st["hotplug"]["attached"], true) << st.dump();
  EXPECT_EQ(st["hotplug"]["reattaches"], 1);
  EXPECT_EQ(st["lease"]["name"], "holder");
  EXPECT_EQ(d.daemon.terminate(std::chrono::milliseconds(2000)), 0);
}

// Every bridge chip's transport (libusb-style for FTDI/CH341A/CP2130, HID for MCP2210) reports the
// unplug through its own driver, and every board comes back.
class DaemonHotplugChips : public ::testing::TestWithParam<std::string> {};

TEST_P(DaemonHotplugChips, UnplugAndReplugAreNoticedWithoutClientTraffic) {
  HotplugDaemon d;
  ASSERT_TRUE(d.start("hp-" + GetParam().substr(0, 6), {}, GetParam())) << d.daemon.error();
  auto watcher = client::Client::connect("unix:" + d.socket, 2000ms);
  ASSERT_TRUE(watcher);
  ASSERT_TRUE(watcher->handshake("watcher", "", 2000ms));
  unplug(d.presence);
  const auto gone = wait_event(*watcher, "device_gone", 5000ms);
  ASSERT_TRUE(gone) << "no device_gone event after the unplug";
  EXPECT_EQ(status_of(*watcher)["backend"], "sim");
  plug(d.presence);
  const auto back = wait_event(*watcher, "device_back", 5000ms);
  ASSERT_TRUE(back) << "no device_back event after the replug";
  EXPECT_EQ((*back)["board"], GetParam());
  const auto st = status_of(*watcher);
  EXPECT_EQ(st["backend"], "board") << st.dump();
  EXPECT_EQ(st["board"], GetParam());
  EXPECT_EQ(st["hotplug"]["reattaches"], 1);
  EXPECT_EQ(d.daemon.terminate(std::chrono::milliseconds(2000)), 0);
}

INSTANTIATE_TEST_SUITE_P(FourBridgeChips, DaemonHotplugChips, test::kFourBridgeChips, test::chip_test_name);

TEST(DaemonHotplugErrors, BadOptionsAreNamed) {
  const auto dir = make_temp_dir("hp-err");
  const auto sock = "unix:" + (dir / "d.sock").string();
  {
    const auto r = run_process({GPUBRIDGED_PATH, "--listen", sock, "--backend", std::string("emulated:") + kBoard + "?presense=/x"});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("unknown option \"presense=/x\""), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("presence=PATH"), std::string::npos) << r.err;
  }
  {  // the emulated adapter is "not plugged in" at start: the same message shape as a missing real adapter
    const auto absent = (dir / "absent").string();
    const auto r = run_process({GPUBRIDGED_PATH, "--listen", sock, "--backend", std::string("emulated:") + kBoard + "?presence=" + absent});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("no USB device 0403:6014"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(absent), std::string::npos) << r.err;
  }
  {
    const auto r = run_process({GPUBRIDGED_PATH, "--listen", sock, "--reattach-interval-ms", "3600001"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("reattach_interval_ms"), std::string::npos) << r.err;
  }
  {
    const auto cfg = dir / "c.json";
    std::ofstream(cfg) << R"({"reattach_interval_ms": -5})";
    const auto r = run_process({GPUBRIDGED_PATH, "--config", cfg.string(), "--listen", sock});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("reattach_interval_ms: expected an integer 0..3600000"), std::string::npos) << r.err;
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace gpubridge::test
