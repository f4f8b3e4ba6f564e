// Mirror mode (issue 6, hardware-in-the-loop bring-up): gpubridged runs a board and the simulator
// side by side and serves the board's frames, the simulator's frames or their difference image.
// - A real gpubridged on an emulated board (`--backend emulated:icebreaker --mirror`) plays a trace:
//   the board frame and the simulator frame both equal `gpubridge render` of the trace, the diff is
//   all grey, and status reports 0 mismatches.
// - A CRC-only board (ch341a-generic) is still compared through FRAME_CRC.
// - A board whose video memory is changed behind the host's back (one pixel of the emulated
//   board's VRAM, as a stuck bit or a stray write would) gives a CRC mismatch, and the diff frame
//   is magenta exactly at that pixel.
// - Without --mirror, SUBSCRIBE source sim/diff is refused with UNAVAILABLE.
// - STATUS and `gpubridge status` report the decorator's own counters as they change: commands the
//   simulator refused but the board accepted (a model with less memory than the board), swaps
//   without a partner (a board with scanout "off"), intermediate simulator swaps of one batch.
#include <gtest/gtest.h>

#include <fstream>
#include <future>
#include <thread>

#include <nlohmann/json.hpp>

#include "client_checks.hpp"
#include "daemon_process.hpp"
#include "in_process_daemon.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/common/image.hpp"
#include "gpubridge/common/trace_files.hpp"
#include "gpubridge/daemon/config.hpp"
#include "gpubridge/daemon/frame_diff.hpp"
#include "gpubridge/daemon/hub.hpp"
#include "gpubridge/daemon/mirror_backend.hpp"
#include "gpubridge/daemon/server.hpp"
#include "gpubridge/daemon/test_backends.hpp"
#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/pixel.hpp"

#include "gpubridge/sim/device.hpp"
#include "gpubridge/sim/sim_backend.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"

namespace gpubridge::test {
namespace {

using namespace std::chrono_literals;
using protocol::FrameFormat;
using protocol::FrameSource;

const std::string kTrace = std::string(GPUBRIDGE_TEST_DATA) + "/board_triangles.trace";  // 64x48 RGB565

// The documented diff colours (docs/protocol.md, SUBSCRIBE source 2), written out here rather
// than taken from the daemon's code.
bool is_magenta(const std::uint8_t* p) { return p[0] == 255 && p[1] == 0 && p[2] == 255 && p[3] == 255; }
bool is_dimmed_grey_of(const std::uint8_t* diff, const std::uint8_t* board_rgba) {
  const unsigned luma = (77u * board_rgba[0] + 150u * board_rgba[1] + 29u * board_rgba[2]) >> 8;
  const unsigned grey = luma / 2;
  return diff[0] == grey && diff[1] == grey && diff[2] == grey && diff[3] == 255;
}

Image to_image(const client::ReceivedFrame& f) { return image_from_device(f.format, f.width, f.height, f.pixels); }


std::unique_ptr<client::Client> subscriber(const std::string& address, FrameSource source,
                                           FrameFormat format = FrameFormat::Native) {
  auto c = client::Client::connect(address, 2000ms);
  if (!c) return nullptr;
  auto owned = std::make_unique<client::Client>(std::move(*c));
  if (!owned->handshake(std::string("sub-") + std::string(protocol::to_string(source)), "", 2000ms)) return nullptr;
  auto sub = owned->subscribe(protocol::Subscribe{format, 0, source}, 2000ms);
  EXPECT_TRUE(sub) << (sub ? "" : sub.error().message);
  return sub ? std::move(owned) : nullptr;
}

TEST(MirrorConfig, KeyIsABooleanAndOffByDefault) {
  auto off = daemon::parse_config(nlohmann::json::parse("{}"), "c.json");
  ASSERT_TRUE(off);
  EXPECT_FALSE(off->mirror);
  auto on = daemon::parse_config(nlohmann::json::parse(R"({"backend": "emulated:icebreaker", "mirror": true})"), "c.json");
  ASSERT_TRUE(on) << on.error().message;
  EXPECT_TRUE(on->mirror);
  auto bad = daemon::parse_config(nlohmann::json::parse(R"({"mirror": "yes"})"), "c.json");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("c.json: mirror: expected true or false"), std::string::npos) << bad.error().message;
}

// `accuracy` (--accuracy): "preview" or a list of settings, checked when the file is read; the
// effective configuration keeps it.
TEST(AccuracyConfig, PreviewOrSettingsCheckedWhenRead) {
  auto one = daemon::parse_config(nlohmann::json::parse(R"({"accuracy": "preview"})"), "c.json");
  ASSERT_TRUE(one) << one.error().message;
  EXPECT_EQ(one->accuracy, std::vector<std::string>{"preview"});
  EXPECT_EQ(daemon::config_to_json(*one)["accuracy"], nlohmann::json::parse(R"(["preview"])"));
  auto list = daemon::parse_config(nlohmann::json::parse(R"({"accuracy": ["preview", "z_bits=16"]})"), "c.json");
  ASSERT_TRUE(list) << list.error().message;
  auto retired = daemon::parse_config(nlohmann::json::parse(R"({"accuracy": "fast=1"})"), "c.json");
  ASSERT_FALSE(retired);
  EXPECT_NE(retired.error().message.find("c.json: accuracy: accuracy knob 'fast' was retired"), std::string::npos)
      << retired.error().message;
  auto wrong = daemon::parse_config(nlohmann::json::parse(R"({"accuracy": 3})"), "c.json");
  ASSERT_FALSE(wrong);
  EXPECT_NE(wrong.error().message.find("c.json: accuracy: expected"), std::string::npos) << wrong.error().message;
  daemon::DaemonConfig no_table;
  no_table.accuracy = {"preview", "recip_bits=8"};
  auto refused = daemon::finalize_config(no_table);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("no reciprocal table"), std::string::npos) << refused.error().message;
}

// A daemon on the simulator with --accuracy preview says so in its WELCOME and STATUS (the viewer's
// overlay shows it).
TEST(DaemonAccuracy, WelcomeAndStatusSayPreview) {
  const auto dir = make_temp_dir("accuracy");
  const std::string address = "unix:" + (dir / "d.sock").string();
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", address, "--backend", "sim", "--accuracy", "preview", "--log-level", "warn"}))
      << daemon.error();
  auto sub = subscriber(address, FrameSource::Board);
  ASSERT_TRUE(sub);
  EXPECT_EQ(nlohmann::json::parse(sub->session().device_json).value("accuracy", ""), "preview");
  const auto status = run_process({GPUBRIDGE_CLI_PATH, "status", "--connect", address, "--json"});
  ASSERT_EQ(status.exit_code, 0) << status.err;
  EXPECT_EQ(nlohmann::json::parse(status.out).value("accuracy", ""), "preview") << status.out;
}

backends::ScanoutFrame make_frame(unsigned w, unsigned h, protocol::PixelFormat f, std::vector<std::uint8_t> px) {
  backends::ScanoutFrame out;
  out.number = 7;
  out.width = w;
  out.height = h;
  out.format = f;
  out.pixels = std::move(px);
  return out;
}

TEST(FrameDiff, ComparesExpandedPixelsAndMarksEveryDifference) {
  using protocol::PixelFormat;
  // 2x1 RGB565 board: pure red, then white. Model in RGBA8888: the same red, a different second pixel.
  const auto board = make_frame(2, 1, PixelFormat::RGB565, {0xF8, 0x00, 0xFF, 0xFF});
  const auto model = make_frame(2, 1, PixelFormat::RGBA8888, {255, 0, 0, 255, 255, 255, 254, 255});
  std::uint64_t differing = 0;
  auto d = daemon::diff_frame(board, model, &differing);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->number, 7u);
  EXPECT_EQ(d->format, PixelFormat::RGBA8888);
  EXPECT_EQ(differing, 1u);
  const unsigned red_grey = (77u * 255 >> 8) / 2;  // 38
  EXPECT_EQ(d->pixels, (std::vector<std::uint8_t>{std::uint8_t(red_grey), std::uint8_t(red_grey),
                                                   std::uint8_t(red_grey), 255, 255, 0, 255, 255}));
  EXPECT_EQ(d->crc, protocol::crc32(d->pixels));
  // Different sizes differ everywhere; a CRC-only board frame has no diff.
  const auto bigger = make_frame(3, 1, PixelFormat::RGBA8888, std::vector<std::uint8_t>(12, 0));
  auto all = daemon::diff_frame(board, bigger, &differing);
  ASSERT_NE(all, nullptr);
  EXPECT_EQ(differing, 2u);
  EXPECT_EQ(daemon::diff_frame(make_frame(2, 1, PixelFormat::RGB565, {}), model), nullptr);
}

// The decorator on its own, with two FakeScanoutBackends (a board of 64 KiB, a model of 4 KiB).
TEST(MirrorBackend, ForwardsToBothAnswersFromTheBoardAndPairsSwaps) {
  auto board_owned = std::make_unique<daemon::FakeScanoutBackend>(8, 4, 64 * 1024);
  auto model_owned = std::make_unique<daemon::FakeScanoutBackend>(8, 4, 4 * 1024);
  auto* board = board_owned.get();
  auto* model = model_owned.get();
  daemon::MirrorBackend mirror(std::move(board_owned), std::move(model_owned));
  std::vector<std::shared_ptr<const backends::ScanoutFrame>> got;
  mirror.set_scanout_callback([&](std::shared_ptr<const backends::ScanoutFrame> f) { got.push_back(std::move(f)); });

  // Writes reach both sides.
  protocol::FramesCmd color;
  color.push(protocol::write_frame(protocol::Reg::CLEAR_COLOR, 0x11223344));
  ASSERT_TRUE(mirror.write_frames(color.view()));
  EXPECT_EQ(*board->read_register(protocol::index_of(protocol::Reg::CLEAR_COLOR)), 0x11223344u);
  EXPECT_EQ(*model->read_register(protocol::index_of(protocol::Reg::CLEAR_COLOR)), 0x11223344u);
  // Reads are answered by the board: change the board alone, then read through the mirror.
  protocol::FramesCmd board_only;
  board_only.push(protocol::write_frame(protocol::Reg::CLEAR_COLOR, 0x55667788));
  ASSERT_TRUE(board->write_frames(board_only.view()));
  EXPECT_EQ(*mirror.read_register(protocol::index_of(protocol::Reg::CLEAR_COLOR)), 0x55667788u);

  // An upload the board takes and the model refuses succeeds for the client and is counted.
  const std::vector<std::uint8_t> bytes(16, 0xAB);
  EXPECT_TRUE(mirror.upload(32 * 1024, bytes));
  EXPECT_EQ(mirror.counters().model_errors, 1u);
  auto back = mirror.readback(32 * 1024, 16);
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, bytes);

  // A mirrored swap: one frame, the board's, with the model's frame as reference.
  protocol::FramesCmd swap;
  swap.push(protocol::write_frame(protocol::Reg::FB_DISPLAY, 0));
  ASSERT_TRUE(mirror.write_frames(swap.view()));
  ASSERT_EQ(got.size(), 1u);
  ASSERT_NE(got[0]->reference, nullptr);
  EXPECT_EQ(got[0]->width, 8u);
  EXPECT_EQ(got[0]->reference->width, 8u);

  // Swaps of one side only pair with nothing: counted, not handed out, not kept for later.
  for (int i = 0; i < 6; ++i) ASSERT_TRUE(board->write_frames(swap.view()));
  ASSERT_TRUE(mirror.flush());
  EXPECT_EQ(got.size(), 1u);
  EXPECT_EQ(mirror.counters().unpaired_frames, 6u);
  ASSERT_TRUE(mirror.write_frames(swap.view()));
  ASSERT_EQ(got.size(), 2u);
  EXPECT_NE(got[1]->reference, nullptr);
}

TEST(DaemonMirror, BoardAndSimulatorFramesBothEqualTheInProcessRender) {
  const auto dir = make_temp_dir("mirror");
  const std::string address = "unix:" + (dir / "d.sock").string();
  Daemon daemon;
  // --accuracy preview is for the daemon's own simulators: the mirror's model stays exact (the
  // simulator frames below must equal the exact in-process render).
  ASSERT_TRUE(daemon.start({"--listen", address, "--backend", "emulated:icebreaker", "--mirror", "--no-fallback",
                            "--accuracy", "preview", "--log-level", "warn"}))
      << daemon.error();

  auto board = subscriber(address, FrameSource::Board);
  auto sim = subscriber(address, FrameSource::Sim);
  auto diff = subscriber(address, FrameSource::Diff);
  ASSERT_TRUE(board && sim && diff);
  // The WELCOME tells clients that this daemon mirrors.
  EXPECT_TRUE(nlohmann::json::parse(board->session().device_json).value("mirror", false));

  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", kTrace, "--connect", address});
  ASSERT_EQ(play.exit_code, 0) << play.err << play.out;
  const auto render = run_process({GPUBRIDGE_CLI_PATH, "render", kTrace, "--out", (dir / "ref.png").string()});
  ASSERT_EQ(render.exit_code, 0) << render.err;
  auto want = load_png(dir / "ref.png");
  ASSERT_TRUE(want) << want.error().message;

  auto b = board->next_frame(5000ms);
  auto s = sim->next_frame(5000ms);
  auto d = diff->next_frame(5000ms);
  ASSERT_TRUE(b) << b.error().message;
  ASSERT_TRUE(s) << s.error().message;
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(b->source, FrameSource::Board);
  EXPECT_EQ(s->source, FrameSource::Sim);
  EXPECT_EQ(d->source, FrameSource::Diff);
  EXPECT_EQ(b->number, s->number) << "board and simulator frames of the same swap carry the same number";
  EXPECT_EQ(b->format, protocol::PixelFormat::RGB565);
  EXPECT_EQ(s->format, protocol::PixelFormat::RGB565);
  // The triangles are there (not just the clear colour) ...
  const Image bi = to_image(*b), si = to_image(*s);
  ASSERT_EQ(bi.width, 64u);
  ASSERT_EQ(bi.height, 48u);
  EXPECT_NE(std::vector<std::uint8_t>(bi.pixel(30, 30), bi.pixel(30, 30) + 4),
            std::vector<std::uint8_t>(bi.pixel(63, 47), bi.pixel(63, 47) + 4));
  // ... and both pictures equal the golden in-process render pixel for pixel.
  EXPECT_TRUE(bi.rgba == want->rgba) << "board frame differs from gpubridge render";
  EXPECT_TRUE(si.rgba == want->rgba) << "simulator frame differs from gpubridge render";
  EXPECT_EQ(b->crc, s->crc);

  // The diff of equal pictures: every pixel the dimmed grey of the board's pixel, no magenta.
  ASSERT_EQ(d->format, protocol::PixelFormat::RGBA8888);
  const Image di = to_image(*d);
  ASSERT_EQ(di.width, bi.width);
  ASSERT_EQ(di.height, bi.height);
  std::size_t grey = 0;
  for (unsigned y = 0; y < di.height; ++y)
    for (unsigned x = 0; x < di.width; ++x) grey += is_dimmed_grey_of(di.pixel(x, y), bi.pixel(x, y)) ? 1 : 0;
  EXPECT_EQ(grey, std::size_t{di.width} * di.height);

  const auto status = status_of(*board);
  EXPECT_EQ(status["mirror"]["enabled"], true) << status.dump();
  EXPECT_GE(status["mirror"]["compared"].get<int>(), 1) << status.dump();
  EXPECT_EQ(status["mirror"]["mismatches"], 0) << status.dump();
  EXPECT_TRUE(status["mirror"]["first_mismatch"].is_null()) << status.dump();
  bool sources_listed = false;
  for (const auto& cl : status["clients"]) sources_listed = sources_listed || cl.value("source", "") == "diff";
  EXPECT_TRUE(sources_listed) << status.dump();
  EXPECT_EQ(daemon.terminate(), 0);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// The CLI side of mirror mode: `gpubridge screenshot --source sim` saves the simulator's picture and
// `gpubridge status` prints the comparison count.
TEST(DaemonMirror, CliScreenshotTakesTheSimulatorSourceAndStatusPrintsTheComparison) {
  const auto dir = make_temp_dir("mirror-cli");
  const std::string address = "unix:" + (dir / "d.sock").string();
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", address, "--backend", "emulated:icebreaker", "--mirror", "--no-fallback",
                            "--log-level", "warn"}))
      << daemon.error();
  auto watcher = client::Client::connect(address, 2000ms);
  ASSERT_TRUE(watcher) << watcher.error().message;
  ASSERT_TRUE(watcher->handshake("watcher", "", 2000ms));

  const std::string shot = (dir / "sim.png").string();
  auto screenshot = std::async(std::launch::async, [&] {
    return run_process({GPUBRIDGE_CLI_PATH, "screenshot", "--source", "sim", "--out", shot, "--connect", address,
                        "--json"});
  });
  // Draw only once the screenshot is subscribed, so that it sees this trace's swap.
  bool subscribed = false;
  for (int i = 0; i < 200 && !subscribed; ++i) {
    const auto status = status_of(*watcher);  // named: a temporary would die before the loop body
    for (const auto& cl : status["clients"]) subscribed = subscribed || cl.value("source", "") == "sim";
    if (!subscribed) std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(subscribed);
  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", kTrace, "--connect", address});
  ASSERT_EQ(play.exit_code, 0) << play.err << play.out;
  const auto shot_result = screenshot.get();
  ASSERT_EQ(shot_result.exit_code, 0) << shot_result.err << shot_result.out;
  EXPECT_EQ(nlohmann::json::parse(shot_result.out).value("source", ""), "sim") << shot_result.out;

  const auto render = run_process({GPUBRIDGE_CLI_PATH, "render", kTrace, "--out", (dir / "ref.png").string()});
  ASSERT_EQ(render.exit_code, 0) << render.err;
  auto want = load_png(dir / "ref.png");
  auto got = load_png(shot);
  ASSERT_TRUE(want && got);
  EXPECT_TRUE(got->rgba == want->rgba) << "the simulator screenshot differs from gpubridge render";

  const auto status = run_process({GPUBRIDGE_CLI_PATH, "status", "--connect", address});
  ASSERT_EQ(status.exit_code, 0) << status.err;
  EXPECT_NE(status.out.find("mirror:    0 of 1 frame(s) differ from the simulator"), std::string::npos) << status.out;

  const auto bad = run_process({GPUBRIDGE_CLI_PATH, "screenshot", "--source", "model", "--out", shot, "--connect",
                                address});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("--source"), std::string::npos) << bad.err;
  watcher->close();
  EXPECT_EQ(daemon.terminate(), 0);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// A board reads FRAME_CRC (and the pixels) once per batch, so of several swaps in one WRITE_FRAMES it
// reports the last; the simulator reports each. The last ones are compared, not the first.
TEST(DaemonMirror, SeveralSwapsInOneBatchCompareTheLastSwap) {
  const auto dir = make_temp_dir("mirror-batch");
  const std::string address = "unix:" + (dir / "d.sock").string();
  const auto trace = (dir / "three.trace").string();
  std::ofstream(trace) << "FB_FORMAT FORMAT=RGB565 WIDTH=64 HEIGHT=48\n"
                          "CLEAR_COLOR R=255 A=255\nCLEAR\nFB_DISPLAY 0\n"
                          "CLEAR_COLOR G=255 A=255\nCLEAR\nFB_DISPLAY 0\n"
                          "CLEAR_COLOR B=255 A=255\nCLEAR\nFB_DISPLAY 0\n";
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", address, "--backend", "emulated:icebreaker", "--mirror", "--no-fallback",
                            "--log-level", "warn"}))
      << daemon.error();
  auto sim = subscriber(address, FrameSource::Sim);
  auto board = subscriber(address, FrameSource::Board);
  ASSERT_TRUE(sim && board);
  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", trace, "--connect", address});
  ASSERT_EQ(play.exit_code, 0) << play.err << play.out;
  auto s = sim->next_frame(5000ms);
  auto b = board->next_frame(5000ms);
  ASSERT_TRUE(s) << s.error().message;
  ASSERT_TRUE(b) << b.error().message;
  // The simulator counted three swaps, the board one: the pictures carry the board's number.
  EXPECT_EQ(s->number, b->number);
  EXPECT_EQ(s->swap_ns, b->swap_ns);
  EXPECT_EQ(s->crc, b->crc);
  const Image si = to_image(*s);
  EXPECT_EQ(si.pixel(10, 10)[2], 255) << "the simulator picture of the batch is its last swap (blue)";
  EXPECT_EQ(si.pixel(10, 10)[0], 0);
  const auto status = status_of(*sim);
  EXPECT_EQ(status["mirror"]["mismatches"], 0) << status.dump();
  EXPECT_GE(status["mirror"]["compared"].get<int>(), 1) << status.dump();
  // The simulator's first two swaps of the batch had no board counterpart: skipped, not unpaired.
  EXPECT_EQ(status["mirror"]["coalesced_swaps"], 2) << status.dump();
  EXPECT_EQ(status["mirror"]["unpaired_frames"], 0) << status.dump();
  EXPECT_EQ(status["mirror"]["model_errors"], 0) << status.dump();
  EXPECT_EQ(daemon.terminate(), 0);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// A board that is unplugged and comes back gets a new mirror decorator; STATUS keeps adding up
// (real gpubridged; the emulated FT232H is present only while the presence file exists).
TEST(DaemonMirror, CountersAddUpAcrossAnUnplugAndReattach) {
  const auto dir = make_temp_dir("mirror-hotplug");
  const auto presence = dir / "present";
  const std::string address = "unix:" + (dir / "d.sock").string();
  const auto trace = (dir / "two.trace").string();
  std::ofstream(trace) << "FB_FORMAT FORMAT=RGB565 WIDTH=64 HEIGHT=48\n"
                          "CLEAR_COLOR R=255 A=255\nCLEAR\nFB_DISPLAY 0\n"
                          "CLEAR_COLOR G=255 A=255\nCLEAR\nFB_DISPLAY 0\n";
  std::ofstream(presence) << "plugged\n";
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", address, "--backend", "emulated:ft232h-generic?presence=" + presence.string(),
                            "--mirror", "--reattach-interval-ms", "50", "--log-level", "warn"}))
      << daemon.error();
  auto watcher = client::Client::connect(address, 2000ms);
  ASSERT_TRUE(watcher);
  ASSERT_TRUE(watcher->handshake("watcher", "", 2000ms));
  const auto coalesced = [&] { return status_of(*watcher)["mirror"]["coalesced_swaps"]; };

  auto play = run_process({GPUBRIDGE_CLI_PATH, "play", trace, "--connect", address});
  ASSERT_EQ(play.exit_code, 0) << play.err << play.out;
  EXPECT_EQ(coalesced(), 1);

  fs::remove(presence);
  ASSERT_TRUE(wait_event(*watcher, "device_gone", 5000ms)) << "no device_gone event after the unplug";
  EXPECT_EQ(coalesced(), 1) << "the unplugged board's mirror counted one skipped swap";
  std::ofstream(presence) << "plugged\n";
  ASSERT_TRUE(wait_event(*watcher, "device_back", 5000ms)) << "no device_back event after the replug";
  EXPECT_EQ(status_of(*watcher)["hotplug"]["reattaches"], 1);

  play = run_process({GPUBRIDGE_CLI_PATH, "play", trace, "--connect", address});
  ASSERT_EQ(play.exit_code, 0) << play.err << play.out;
  EXPECT_EQ(coalesced(), 2) << "one from the first board's mirror, one from the re-attached board's";
  watcher->close();
  EXPECT_EQ(daemon.terminate(), 0);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// ch341a-generic ships "scanout": "crc": the board gives no pixels, only FRAME_CRC. The comparison
// still happens (CRC against the simulator's CRC); simulator subscribers still get pictures.
TEST(DaemonMirror, CrcOnlyBoardIsComparedThroughFrameCrc) {
  const auto dir = make_temp_dir("mirror-crc");
  const std::string address = "unix:" + (dir / "d.sock").string();
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", address, "--backend", "emulated:ch341a-generic", "--mirror", "--no-fallback",
                            "--log-level", "warn"}))
      << daemon.error();
  auto board = subscriber(address, FrameSource::Board);
  auto sim = subscriber(address, FrameSource::Sim);
  ASSERT_TRUE(board && sim);
  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", kTrace, "--connect", address});
  ASSERT_EQ(play.exit_code, 0) << play.err << play.out;
  auto s = sim->next_frame(5000ms);
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->width, 64u);
  EXPECT_FALSE(board->next_frame(300ms)) << "a CRC-only board produced a board picture";
  const auto status = status_of(*sim);
  EXPECT_GE(status["mirror"]["compared"].get<int>(), 1) << status.dump();
  EXPECT_EQ(status["mirror"]["mismatches"], 0) << status.dump();
  EXPECT_EQ(daemon.terminate(), 0);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// `gpubridge screenshot` of a CRC-only board (issue 15): frames are scanned out while it waits but
// none carries a board picture; it says so (and how to see them) instead of "is anything drawing?".
TEST(DaemonMirror, ScreenshotOfACrcOnlyBoardSaysFramesCameWithoutPictures) {
  const auto dir = make_temp_dir("shot-crc");
  const std::string address = "unix:" + (dir / "d.sock").string();
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", address, "--backend", "emulated:ch341a-generic", "--no-fallback",
                            "--log-level", "warn"}))
      << daemon.error();
  auto watcher = client::Client::connect(address, 2000ms);
  ASSERT_TRUE(watcher) << watcher.error().message;
  ASSERT_TRUE(watcher->handshake("watcher", "", 2000ms));
  auto screenshot = std::async(std::launch::async, [&] {
    return run_process({GPUBRIDGE_CLI_PATH, "screenshot", "--out", (dir / "none.png").string(), "--timeout", "4000",
                        "--connect", address});
  });
  bool subscribed = false;
  for (int i = 0; i < 200 && !subscribed; ++i) {
    const auto status = status_of(*watcher);  // named: a temporary would die before the loop body
    for (const auto& cl : status["clients"]) subscribed = subscribed || cl.value("subscribed", false);
    if (!subscribed) std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(subscribed);
  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", kTrace, "--connect", address});
  ASSERT_EQ(play.exit_code, 0) << play.err << play.out;
  const auto r = screenshot.get();
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("the daemon scanned out 1 frame(s) while we waited 4 s, but no board picture of them reached "
                       "this client"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("\"scanout\": \"crc\""), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("nothing is drawing"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "none.png"));
  watcher->close();
  EXPECT_EQ(daemon.terminate(), 0);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

TEST(DaemonMirror, WithoutMirrorModeSimAndDiffAreRefusedButBoardStillWorks) {
  const auto dir = make_temp_dir("mirror-off");
  const std::string address = "unix:" + (dir / "d.sock").string();
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", address, "--log-level", "warn"})) << daemon.error();
  auto c = client::Client::connect(address, 2000ms);
  ASSERT_TRUE(c);
  ASSERT_TRUE(c->handshake("no-mirror", "", 2000ms));
  EXPECT_FALSE(nlohmann::json::parse(c->session().device_json).value("mirror", true));
  for (auto source : {FrameSource::Sim, FrameSource::Diff}) {
    auto r = c->subscribe(protocol::Subscribe{FrameFormat::Native, 0, source}, 2000ms);
    ASSERT_FALSE(r) << protocol::to_string(source);
    EXPECT_TRUE(client::is_protocol_error(r.error(), protocol::ErrorCode::Unavailable)) << r.error().message;
    EXPECT_NE(r.error().message.find("--mirror"), std::string::npos) << r.error().message;
  }
  // The refusal is not fatal: the same session subscribes to the board (old 3-byte form) and gets frames.
  ASSERT_TRUE(c->subscribe(FrameFormat::Native, 0, 2000ms));
  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", kTrace, "--connect", address});
  ASSERT_EQ(play.exit_code, 0) << play.err << play.out;
  auto f = c->next_frame(5000ms);
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->source, FrameSource::Board);
  EXPECT_EQ(daemon.terminate(), 0);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

TEST(DaemonMirror, MirrorNeedsABoardBackend) {
  const auto dir = make_temp_dir("mirror-sim");
  const auto r = run_process({GPUBRIDGED_PATH, "--listen", "unix:" + (dir / "d.sock").string(), "--backend", "sim", "--mirror"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("--mirror needs a board backend"), std::string::npos) << r.err;
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// The tampered board: the hub, sessions and sockets are the daemon's own code, run in-process so
// the test can reach the emulated board's video memory below the USB driver.
// How the in-process mirror differs from what `gpubridged --mirror` builds (defaults: not at all).
struct MirrorSetup {
  usb::ScanoutMode scanout = usb::ScanoutMode::Readback;  // the emulated icebreaker's profile value
  std::uint64_t model_vram_bytes = 0;  // > 0: a simulator with this much memory instead of the board's
};

class InProcessMirrorDaemon {
 public:
  bool start(const fs::path& dir, std::string& why, const MirrorSetup& setup = {}) {
    auto profile = usb::find_board_profile(fs::path(GPUBRIDGE_BOARDS_DIR).parent_path(), "icebreaker");
    if (!profile) return (why = profile.error().message, false);
    profile->scanout = setup.scanout;
    auto emulated = usb::emu::open_emulated_board(*profile);
    if (!emulated) return (why = emulated.error().message, false);
    stack_ = emulated->stack;
    if (!stack_->target_is_simulator()) return (why = "emulated board without the simulator's device model", false);
    std::unique_ptr<backends::Backend> mirror;
    if (setup.model_vram_bytes == 0) {
      auto made = daemon::make_mirror(std::move(emulated->backend));
      if (!made) return (why = made.error().message, false);
      mirror = std::move(*made);
    } else {
      sim::DeviceOptions o;
      o.vram_bytes = setup.model_vram_bytes;
      auto model = sim::SimBackend::create(o);
      if (!model) return (why = model.error().message, false);
      mirror = std::make_unique<daemon::MirrorBackend>(std::move(emulated->backend), std::move(*model));
    }
    test::InProcessDaemon::Options opts;
    opts.hub.mirror = true;
    return daemon_.start(std::move(mirror), dir, why, opts);
  }
  const std::string& address() const { return daemon_.address(); }
  // Changes the board's video memory on the device thread, between commands, like a stray write
  // the host never sent.
  void poke_board_memory(std::size_t offset, std::uint8_t xor_mask) {
    std::promise<void> done;
    boost::asio::post(daemon_.device_context(), [&] {
      auto& device = dynamic_cast<sim::Device&>(stack_->target());
      device.memory()[offset] ^= xor_mask;
      done.set_value();
    });
    done.get_future().wait();
  }

 private:
  std::shared_ptr<usb::emu::EmulatedStack> stack_;  // declared first: outlives the daemon using it
  test::InProcessDaemon daemon_;
};

// Sends board_triangles.trace's register writes (one swap of the 64x48 RGB565 framebuffer at
// address 0) through a client holding the lease, then fences.
void play_triangles(client::Client& player) {
  auto trace = load_trace(kTrace);
  ASSERT_TRUE(trace) << trace.error().message;
  for (const auto& tc : trace->commands) {
    if (std::holds_alternative<protocol::FenceCmd>(tc.command)) continue;  // fenced once below
    const auto* frames = std::get_if<protocol::FramesCmd>(&tc.command);
    ASSERT_NE(frames, nullptr) << "board_triangles.trace is expected to hold register writes only";
    ASSERT_TRUE(player.write_frames(frames->view(), 2000ms));
  }
  ASSERT_TRUE(player.fence(5000ms));
}

TEST(DaemonMirror, TamperedBoardMemoryIsCountedAndShownMagentaExactlyWhereItDiffers) {
  const auto dir = make_temp_dir("mirror-tamper");
  InProcessMirrorDaemon daemon;
  std::string why;
  ASSERT_TRUE(daemon.start(dir, why)) << why;
  auto board = subscriber(daemon.address(), FrameSource::Board);
  auto sim = subscriber(daemon.address(), FrameSource::Sim);
  auto diff = subscriber(daemon.address(), FrameSource::Diff);
  ASSERT_TRUE(board && sim && diff);

  auto player = client::Client::connect(daemon.address(), 2000ms);
  ASSERT_TRUE(player);
  ASSERT_TRUE(player->handshake("player", "", 2000ms));
  ASSERT_TRUE(player->acquire_lease(protocol::LeaseMode::Wait, 2000ms));
  ASSERT_NO_FATAL_FAILURE(play_triangles(*player));
  // Swap 1: untouched, equal.
  auto b1 = board->next_frame(5000ms);
  auto d1 = diff->next_frame(5000ms);
  ASSERT_TRUE(b1 && d1);
  auto status = status_of(*player);
  EXPECT_EQ(status["mirror"]["mismatches"], 0) << status.dump();
  EXPECT_TRUE(status["mirror"]["first_mismatch_pixels"].is_null()) << status.dump();

  // One pixel of the displayed RGB565 framebuffer at address 0 changes on the board only.
  const unsigned tx = 37, ty = 21;
  daemon.poke_board_memory((std::size_t{ty} * 64 + tx) * 2 + 1, 0x5A);
  protocol::FramesCmd swap;
  swap.push(protocol::write_frame(protocol::Reg::FB_DISPLAY, 0));
  ASSERT_TRUE(player->write_frames(swap.view(), 2000ms));
  ASSERT_TRUE(player->fence(5000ms));

  auto b2 = board->next_frame(5000ms);
  auto s2 = sim->next_frame(5000ms);
  auto d2 = diff->next_frame(5000ms);
  ASSERT_TRUE(b2) << b2.error().message;
  ASSERT_TRUE(s2) << s2.error().message;
  ASSERT_TRUE(d2) << d2.error().message;
  ASSERT_EQ(b2->number, s2->number);
  ASSERT_EQ(d2->number, b2->number);
  EXPECT_NE(b2->crc, s2->crc);
  const Image bi = to_image(*b2), si = to_image(*s2), di = to_image(*d2);
  ASSERT_EQ(di.width, 64u);
  ASSERT_EQ(di.height, 48u);
  // The test's own comparison of the two pictures: exactly the poked pixel differs ...
  std::vector<std::pair<unsigned, unsigned>> differing;
  for (unsigned y = 0; y < bi.height; ++y)
    for (unsigned x = 0; x < bi.width; ++x)
      if (!std::equal(bi.pixel(x, y), bi.pixel(x, y) + 4, si.pixel(x, y))) differing.emplace_back(x, y);
  ASSERT_EQ(differing.size(), 1u);
  EXPECT_EQ(differing[0], std::make_pair(tx, ty));
  // ... and the diff is magenta there and the dimmed grey of the board pixel everywhere else.
  for (unsigned y = 0; y < di.height; ++y)
    for (unsigned x = 0; x < di.width; ++x) {
      if (x == tx && y == ty)
        EXPECT_TRUE(is_magenta(di.pixel(x, y))) << x << "," << y;
      else
        ASSERT_TRUE(is_dimmed_grey_of(di.pixel(x, y), bi.pixel(x, y))) << x << "," << y;
    }

  status = status_of(*player);
  EXPECT_EQ(status["mirror"]["compared"], 2) << status.dump();
  EXPECT_EQ(status["mirror"]["mismatches"], 1) << status.dump();
  EXPECT_EQ(status["mirror"]["first_mismatch"], b2->number) << status.dump();
  EXPECT_EQ(status["mirror"]["first_mismatch_pixels"], differing.size()) << status.dump();
  EXPECT_EQ(status["mirror"]["last_mismatch_pixels"], differing.size()) << status.dump();

  // Two more board pixels change: the latest mismatch counts three, the first one keeps its one.
  daemon.poke_board_memory((std::size_t{3} * 64 + 5) * 2, 0x81);
  daemon.poke_board_memory((std::size_t{40} * 64 + 60) * 2 + 1, 0x18);
  ASSERT_TRUE(player->write_frames(swap.view(), 2000ms));
  ASSERT_TRUE(player->fence(5000ms));
  auto b3 = board->next_frame(5000ms);
  auto s3 = sim->next_frame(5000ms);
  ASSERT_TRUE(b3 && s3);
  ASSERT_EQ(b3->number, s3->number);
  const Image bi3 = to_image(*b3), si3 = to_image(*s3);
  std::uint64_t differing3 = 0;
  for (unsigned y = 0; y < bi3.height; ++y)
    for (unsigned x = 0; x < bi3.width; ++x) differing3 += !std::equal(bi3.pixel(x, y), bi3.pixel(x, y) + 4, si3.pixel(x, y));
  ASSERT_EQ(differing3, 3u) << "the pixel poked before and the two poked now";
  status = status_of(*player);
  EXPECT_EQ(status["mirror"]["mismatches"], 2) << status.dump();
  EXPECT_EQ(status["mirror"]["first_mismatch"], b2->number) << status.dump();
  EXPECT_EQ(status["mirror"]["last_mismatch"], b3->number) << status.dump();
  EXPECT_EQ(status["mirror"]["first_mismatch_pixels"], 1) << status.dump();
  EXPECT_EQ(status["mirror"]["last_mismatch_pixels"], differing3) << status.dump();
  const auto text = run_process({GPUBRIDGE_CLI_PATH, "status", "--connect", daemon.address()});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("latest #" + std::to_string(b3->number) + ", 3 pixel(s) differ"), std::string::npos) << text.out;
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// The counters of STATUS's `mirror` object that a test reads as one line.
struct Counted {
  std::uint64_t model_errors, unpaired, coalesced, compared, mismatches;
  bool operator==(const Counted&) const = default;
};
std::ostream& operator<<(std::ostream& os, const Counted& c) {
  return os << "{model_errors " << c.model_errors << ", unpaired " << c.unpaired << ", coalesced " << c.coalesced
            << ", compared " << c.compared << ", mismatches " << c.mismatches << "}";
}
Counted counted(const nlohmann::json& status) {
  const auto& m = status.at("mirror");
  return {m.at("model_errors").get<std::uint64_t>(), m.at("unpaired_frames").get<std::uint64_t>(),
          m.at("coalesced_swaps").get<std::uint64_t>(), m.at("compared").get<std::uint64_t>(),
          m.at("mismatches").get<std::uint64_t>()};
}

// The board (emulated icebreaker, 128 KiB) is mirrored by a simulator with only 64 KiB, so the
// upper half of the board's memory is where the model refuses what the board accepts.
TEST(DaemonMirror, StatusAndCliReportTheMirrorsOwnCountersAsTheyChange) {
  const auto dir = make_temp_dir("mirror-counters");
  InProcessMirrorDaemon daemon;
  std::string why;
  ASSERT_TRUE(daemon.start(dir, why, MirrorSetup{.model_vram_bytes = 64 * 1024})) << why;
  auto board = subscriber(daemon.address(), FrameSource::Board);
  auto sim = subscriber(daemon.address(), FrameSource::Sim);
  ASSERT_TRUE(board && sim);
  auto player = client::Client::connect(daemon.address(), 2000ms);
  ASSERT_TRUE(player);
  ASSERT_TRUE(player->handshake("player", "", 2000ms));
  ASSERT_TRUE(player->acquire_lease(protocol::LeaseMode::Wait, 2000ms));
  EXPECT_EQ(counted(status_of(*player)), (Counted{0, 0, 0, 0, 0}));

  // Upload and readback in the board's upper half: the client gets the board's success and data,
  // each refusal of the 64 KiB simulator is counted.
  const std::uint32_t high = 96 * 1024;
  const std::vector<std::uint8_t> bytes(64, 0xA5);
  ASSERT_TRUE(player->upload(high, bytes, {}, 2000ms));
  EXPECT_EQ(counted(status_of(*player)), (Counted{1, 0, 0, 0, 0}));
  auto back = player->readback(high, 64, {}, 2000ms);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(*back, bytes);
  EXPECT_EQ(counted(status_of(*player)), (Counted{2, 0, 0, 0, 0}));

  // A swap inside both memories is compared, and equal.
  ASSERT_NO_FATAL_FAILURE(play_triangles(*player));
  ASSERT_TRUE(board->next_frame(5000ms));
  EXPECT_EQ(counted(status_of(*player)), (Counted{2, 0, 0, 1, 0}));

  // Two swaps in one batch: the board reports the last, the simulator's first is skipped.
  protocol::FramesCmd twice;
  twice.push(protocol::write_frame(protocol::Reg::FB_DISPLAY, 0));
  twice.push(protocol::write_frame(protocol::Reg::FB_DISPLAY, 0));
  ASSERT_TRUE(player->write_frames(twice.view(), 2000ms));
  ASSERT_TRUE(player->fence(5000ms));
  ASSERT_TRUE(board->next_frame(5000ms));
  EXPECT_EQ(counted(status_of(*player)), (Counted{2, 0, 1, 2, 0}));
  EXPECT_TRUE(status_of(*player)["mirror"]["first_mismatch_pixels"].is_null());
  EXPECT_TRUE(status_of(*player)["mirror"]["last_mismatch_pixels"].is_null());

  // Showing the upper half: the board has the uploaded bytes there, the simulator has no memory
  // there (its scanout reads zeros), so the pictures differ; the test counts where.
  protocol::FramesCmd high_swap;
  high_swap.push(protocol::write_frame(protocol::Reg::FB_DISPLAY, high));
  ASSERT_TRUE(player->write_frames(high_swap.view(), 2000ms));
  ASSERT_TRUE(player->fence(5000ms));
  auto b = board->next_frame(5000ms);
  ASSERT_TRUE(b) << b.error().message;
  std::optional<client::ReceivedFrame> s;
  for (int i = 0; i < 3 && (!s || s->number != b->number); ++i) {  // the sim subscriber also has the earlier swaps
    auto next = sim->next_frame(5000ms);
    ASSERT_TRUE(next) << next.error().message;
    s = std::move(*next);
  }
  ASSERT_EQ(s->number, b->number);
  const Image bi = to_image(*b), si = to_image(*s);
  ASSERT_EQ(bi.rgba.size(), si.rgba.size());
  std::uint64_t differing = 0;
  for (unsigned y = 0; y < bi.height; ++y)
    for (unsigned x = 0; x < bi.width; ++x) differing += !std::equal(bi.pixel(x, y), bi.pixel(x, y) + 4, si.pixel(x, y));
  EXPECT_GE(differing, 32u) << "the 64 uploaded bytes are 32 RGB565 pixels the simulator does not have";
  auto status = status_of(*player);
  EXPECT_EQ(counted(status), (Counted{2, 0, 1, 3, 1}));
  EXPECT_EQ(status["mirror"]["first_mismatch"], b->number) << status.dump();
  EXPECT_EQ(status["mirror"]["first_mismatch_pixels"], differing) << status.dump();

  // `gpubridge status`: the same numbers in --json and in the text.
  const auto json = run_process({GPUBRIDGE_CLI_PATH, "status", "--connect", daemon.address(), "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const auto cli = nlohmann::json::parse(json.out);
  EXPECT_EQ(counted(cli), (Counted{2, 0, 1, 3, 1})) << json.out;
  EXPECT_EQ(cli["mirror"]["first_mismatch_pixels"], differing) << json.out;
  const auto text = run_process({GPUBRIDGE_CLI_PATH, "status", "--connect", daemon.address()});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("mirror:    1 of 3 frame(s) differ from the simulator (first #" + std::to_string(b->number) +
                          ", " + std::to_string(differing) + " pixel(s) differ;"),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("2 command(s) the board accepted were refused by the simulator, 0 swap(s) without a "
                          "partner, 1 intermediate simulator swap(s) skipped"),
            std::string::npos)
      << text.out;
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// A board whose profile says "scanout": "off" reports no swaps: every simulator swap is unpaired.
TEST(DaemonMirror, SwapsOfABoardWithoutScanoutAreCountedAsUnpaired) {
  const auto dir = make_temp_dir("mirror-unpaired");
  InProcessMirrorDaemon daemon;
  std::string why;
  ASSERT_TRUE(daemon.start(dir, why, MirrorSetup{.scanout = usb::ScanoutMode::Off})) << why;
  auto player = client::Client::connect(daemon.address(), 2000ms);
  ASSERT_TRUE(player);
  ASSERT_TRUE(player->handshake("player", "", 2000ms));
  ASSERT_TRUE(player->acquire_lease(protocol::LeaseMode::Wait, 2000ms));
  ASSERT_NO_FATAL_FAILURE(play_triangles(*player));
  EXPECT_EQ(counted(status_of(*player)), (Counted{0, 1, 0, 0, 0}));
  ASSERT_NO_FATAL_FAILURE(play_triangles(*player));
  EXPECT_EQ(counted(status_of(*player)), (Counted{0, 2, 0, 0, 0}));
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// The whole path of the gateware backend: client -> gpubridged -> FT2232H driver -> libusb-shaped
// transport -> chip model -> SPI pins -> Verilated iCEBreaker gateware, mirrored by the simulator:
// every frame compared, none differs, and the board's frame equals the in-process render.
TEST(DaemonMirror, GatewareBackendMirroredFrameByFrame) {
#if GPUBRIDGE_HAVE_RTL
  const auto dir = make_temp_dir("mirror-rtl");
  const std::string address = "unix:" + (dir / "d.sock").string();
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", address, "--backend", "rtl:icebreaker", "--mirror", "--no-fallback",
                            "--log-level", "warn"}))
      << daemon.error();
  auto board = subscriber(address, FrameSource::Board);
  ASSERT_TRUE(board);
  EXPECT_NE(board->session().device_json.find("icebreaker"), std::string::npos) << board->session().device_json;
  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", kTrace, "--connect", address}, std::chrono::seconds(120));
  ASSERT_EQ(play.exit_code, 0) << play.err << play.out;
  const auto render = run_process({GPUBRIDGE_CLI_PATH, "render", kTrace, "--out", (dir / "ref.png").string()});
  ASSERT_EQ(render.exit_code, 0) << render.err;
  auto want = load_png(dir / "ref.png");
  ASSERT_TRUE(want) << want.error().message;
  auto b = board->next_frame(60000ms);
  ASSERT_TRUE(b) << b.error().message;
  EXPECT_TRUE(to_image(*b).rgba == want->rgba) << "gateware frame differs from gpubridge render";
  const auto status = status_of(*board);
  EXPECT_GE(status["mirror"]["compared"].get<int>(), 1) << status.dump();
  EXPECT_EQ(status["mirror"]["mismatches"], 0) << status.dump();
  EXPECT_EQ(daemon.terminate(), 0);
  std::error_code ec;
  fs::remove_all(dir, ec);
#else
  GTEST_SKIP() << "built without the rtl backend (Verilator missing)";
#endif
}

}  // namespace
}  // namespace gpubridge::test
