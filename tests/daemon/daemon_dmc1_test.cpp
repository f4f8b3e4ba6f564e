// The DMC-1 behind gpubridged (docs/dmc1.md "Behind the daemon", docs/protocol.md 17.7): every RTL
// golden of tests/dmc1/data played through a real daemon with `gpubridge play` and taken back with
// `gpubridge screenshot` (and as raw RGB565 words by a subscriber), bit for bit; device kinds in
// WELCOME and STATUS; WRONG_DEVICE for the other kind's commands; recordings (played, dumped,
// converted); the board backend streaming to a pseudo-terminal whose other end is the SOC's receiver
// model feeding a second simulator.
#include <algorithm>
#include <atomic>
#include <future>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../dmc1/golden_data.hpp"
#include "../dmc1/pty.hpp"
#include "daemon_fixture.hpp"
#include "daemon_process.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/common/image.hpp"
#include "gpubridge/dmc1/command.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/dmc1/dmc1_backend.hpp"
#include "gpubridge/dmc1/uart.hpp"
#include "gpubridge/protocol/trace.hpp"

namespace gpubridge::test {
namespace {

using namespace std::chrono_literals;
namespace golden = dmc1::test;

std::vector<std::string> cli(std::vector<std::string> args, const std::string& socket) {
  args.insert(args.begin(), GPUBRIDGE_CLI_PATH);
  args.push_back("--connect");
  args.push_back("unix:" + socket);
  return args;
}

client::Client connect_to(const std::string& socket, const std::string& name) {
  auto c = client::Client::connect("unix:" + socket, 2000ms);
  if (!c) throw std::runtime_error(c.error().message);
  if (auto h = c->handshake(name, "", 2000ms); !h) throw std::runtime_error(h.error().message);
  return std::move(*c);
}

// Waits until exactly `n` clients of the daemon are subscribed (a screenshot that exited may still
// count for a moment: waiting for the count to fall first keeps the next one from missing its frame).
::testing::AssertionResult wait_subscribed(client::Client& watcher, int n) {
  for (int i = 0; i < 1000; ++i) {
    auto s = watcher.status(2000ms);
    if (!s) return ::testing::AssertionFailure() << s.error().message;
    const auto status = nlohmann::json::parse(*s);
    int subs = 0;
    for (const auto& cl : status["clients"]) subs += cl["subscribed"].get<bool>();
    if (subs == n) return ::testing::AssertionSuccess();
    std::this_thread::sleep_for(10ms);
  }
  return ::testing::AssertionFailure() << "not " << n << " subscribers after 10 s";
}

class DaemonDmc1 : public DaemonDirTest {};

// Every golden, as the README says: `gpubridged --backend dmc1` (no texture or palette options: the
// repository's DMC-1 data is the default), `gpubridge play STREAM`, `gpubridge screenshot`.
TEST_F(DaemonDmc1, EveryGoldenThroughPlayAndScreenshotBitForBit) {
  ASSERT_TRUE(daemon_.start({"--listen", "unix:" + socket_, "--backend", "dmc1", "--log-level", "warn"})) << daemon_.error();
  auto raw = connect_to(socket_, "raw-subscriber");
  ASSERT_TRUE(raw.subscribe(protocol::FrameFormat::RGB565, 0, 2000ms));
  // The same stream in tinygpus' line format goes through too.
  const auto nfo = dir_ / "mixed.nfo";
  ASSERT_TRUE(dmc1::save_stream(nfo, golden::golden_stream("mixed")));
  std::vector<std::pair<std::string, fs::path>> streams;
  for (const char* name : golden::kGoldenStreams) streams.emplace_back(name, golden::kDataDir / "streams" / (std::string(name) + ".dmc1"));
  streams.emplace_back("mixed", nfo);
  for (const auto& [name, stream] : streams) {
    SCOPED_TRACE(stream.string());
    const auto png = dir_ / (name + ".png");
    ASSERT_TRUE(wait_subscribed(raw, 1));
    auto shot = std::async(std::launch::async, [&] { return run_process(cli({"screenshot", "--out", png.string()}, socket_)); });
    ASSERT_TRUE(wait_subscribed(raw, 2));
    const auto play = run_process(cli({"play", stream.string()}, socket_), 60s);
    ASSERT_EQ(play.exit_code, 0) << play.err;
    EXPECT_NE(play.out.find("DMC-1 command words, 1 frames"), std::string::npos) << play.out;
    const auto s = shot.get();
    ASSERT_EQ(s.exit_code, 0) << s.err;
    const auto want = golden::golden_pixels(name);
    ASSERT_EQ(want.size(), dmc1::kFramePixels);
    // The screenshot: the golden frame's picture (x = column, y = 239 - row), every pixel.
    auto got = load_png(png);
    ASSERT_TRUE(got) << got.error().message;
    EXPECT_TRUE(*got == dmc1::frame_image(want)) << "screenshot of " << name << " differs from the golden";
    // The subscriber's FRAME: the RTL's RGB565 words themselves.
    auto f = raw.next_frame(5000ms);
    ASSERT_TRUE(f) << f.error().message;
    EXPECT_EQ(f->width, dmc1::kColumns);
    EXPECT_EQ(f->height, dmc1::kRows);
    EXPECT_EQ(f->format, protocol::PixelFormat::RGB565);
    EXPECT_TRUE(f->pixels == dmc1::frame_rows_rgb565(want)) << "FRAME of " << name << " differs from the golden";
  }
}

TEST_F(DaemonDmc1, WelcomeAndStatusSayTheDeviceKind) {
  ASSERT_TRUE(daemon_.start({"--listen", "unix:" + socket_, "--backend", "dmc1", "--log-level", "warn"})) << daemon_.error();
  auto c = connect_to(socket_, "kind");
  EXPECT_EQ(c.session().device_kind, protocol::DeviceKind::Dmc1);
  const auto welcome = nlohmann::json::parse(c.session().device_json);
  EXPECT_EQ(welcome.at("device_kind"), "dmc1");
  EXPECT_EQ(welcome.at("max_width"), 320);
  EXPECT_EQ(welcome.at("max_height"), 240);
  auto s = c.status(2000ms);
  ASSERT_TRUE(s) << s.error().message;
  const auto status = nlohmann::json::parse(*s);
  EXPECT_EQ(status.at("device_kind"), "dmc1");
  EXPECT_EQ(status.at("backend"), "sim");
  EXPECT_FALSE(status.contains("frames_note")) << "the simulator's frames are its own";
  const auto st = run_process(cli({"status", "--json"}, socket_));
  ASSERT_EQ(st.exit_code, 0) << st.err;
  EXPECT_EQ(nlohmann::json::parse(st.out).at("device_kind"), "dmc1");
}

// spigpu commands to a DMC-1 and DMC-1 words to a spigpu: ERROR WRONG_DEVICE, not fatal (the
// session goes on), and the CLI says so before it takes the lease.
TEST_F(DaemonDmc1, TheOtherKindsCommandsGetWrongDevice) {
  ASSERT_TRUE(daemon_.start({"--listen", "unix:" + socket_, "--backend", "dmc1", "--log-level", "warn"})) << daemon_.error();
  {
    auto c = connect_to(socket_, "spigpu-client");
    ASSERT_TRUE(c.acquire_lease(protocol::LeaseMode::Wait, 2000ms));
    auto reg = c.read_register(protocol::index_of(protocol::Reg::ID), 2000ms);
    ASSERT_FALSE(reg);
    EXPECT_TRUE(client::is_protocol_error(reg.error(), protocol::ErrorCode::WrongDevice)) << reg.error().message;
    EXPECT_NE(reg.error().message.find("READ_REG is a spigpu command, but this gpubridged serves a DMC-1"), std::string::npos)
        << reg.error().message;
    std::vector<std::uint8_t> frames;
    protocol::append(frames, protocol::write_frame(protocol::Reg::FB_DISPLAY, 0));
    (void)c.write_frames(protocol::FrameView{frames}, 2000ms);
    auto fenced = c.fence(2000ms);
    ASSERT_FALSE(fenced) << "WRITE_FRAMES to a DMC-1 was accepted";
    EXPECT_TRUE(client::is_protocol_error(fenced.error(), protocol::ErrorCode::WrongDevice)) << fenced.error().message;
    // Not fatal: the same session draws DMC-1 words next.
    const auto words = golden::golden_stream("edge");
    ASSERT_TRUE(c.write_dmc1_words(words, 5000ms));
    EXPECT_TRUE(c.fence(10000ms));
  }
  const std::string trace = std::string(GPUBRIDGE_TEST_DATA) + "/triangle.trace";
  const auto play = run_process(cli({"play", trace}, socket_));
  EXPECT_EQ(play.exit_code, 1);
  EXPECT_NE(play.err.find("is a spigpu stream, but the daemon at unix:" + socket_ + " serves a DMC-1"), std::string::npos)
      << play.err;
  daemon_.stop();

  Daemon spigpu;
  const std::string sim_socket = (dir_ / "s.sock").string();
  ASSERT_TRUE(spigpu.start({"--listen", "unix:" + sim_socket, "--backend", "sim", "--log-level", "warn"})) << spigpu.error();
  auto c = connect_to(sim_socket, "dmc1-client");
  EXPECT_EQ(c.session().device_kind, protocol::DeviceKind::Spigpu);
  ASSERT_TRUE(c.acquire_lease(protocol::LeaseMode::Wait, 2000ms));
  (void)c.write_dmc1_words(golden::golden_stream("edge"), 2000ms);
  auto fenced = c.fence(2000ms);
  ASSERT_FALSE(fenced) << "DMC1_WORDS to a spigpu was accepted";
  EXPECT_TRUE(client::is_protocol_error(fenced.error(), protocol::ErrorCode::WrongDevice)) << fenced.error().message;
  EXPECT_NE(fenced.error().message.find("DMC1_WORDS is a DMC-1 command, but this gpubridged serves a spigpu"),
            std::string::npos)
      << fenced.error().message;
  EXPECT_TRUE(c.read_register(protocol::index_of(protocol::Reg::ID), 2000ms)) << "the session went on";
  const auto wrong = run_process(cli({"play", (golden::kDataDir / "streams" / "walls.dmc1").string()}, sim_socket));
  EXPECT_EQ(wrong.exit_code, 1);
  EXPECT_NE(wrong.err.find("is a DMC-1 stream, but the daemon at unix:" + sim_socket + " serves a spigpu"), std::string::npos)
      << wrong.err;
  EXPECT_NE(wrong.err.find("--backend dmc1"), std::string::npos) << wrong.err;
}

// gpubridged --record: a DMC-1 session's binary trace says "device_kind": "dmc1" and holds its words;
// `gpubridge play` takes the recording back to a DMC-1 daemon, and the spigpu trace reader refuses it.
TEST_F(DaemonDmc1, RecordingsSayTheirDeviceKindAndPlayBack) {
  const auto rec = dir_ / "rec";
  fs::create_directories(rec);
  ASSERT_TRUE(daemon_.start({"--listen", "unix:" + socket_, "--backend", "dmc1", "--record", rec.string(), "--log-level", "warn"}))
      << daemon_.error();
  const auto stream = golden::kDataDir / "streams" / "planes.dmc1";
  const auto play = run_process(cli({"play", stream.string()}, socket_), 60s);
  ASSERT_EQ(play.exit_code, 0) << play.err;
  // The session's end (seen by the daemon a moment after play exits) flushes its recording.
  std::vector<fs::path> traces;
  std::vector<std::uint8_t> bytes;
  for (int i = 0; i < 100; ++i) {
    traces.clear();
    for (const auto& e : fs::directory_iterator(rec)) traces.push_back(e.path());
    if (traces.size() == 1 && (bytes = golden::read_bytes(traces[0])).size() > 8 * golden::golden_stream("planes").size()) break;
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_EQ(traces.size(), 1u);
  auto kind = protocol::binary_trace_device_kind(bytes, traces[0].string());
  ASSERT_TRUE(kind) << kind.error().message;
  EXPECT_EQ(*kind, protocol::DeviceKind::Dmc1);
  auto words = protocol::read_dmc1_trace(bytes, traces[0].string());
  ASSERT_TRUE(words) << words.error().message;
  EXPECT_TRUE(*words == golden::golden_stream("planes"));
  auto spigpu = protocol::read_binary_trace(bytes, "rec.gbtrace");
  ASSERT_FALSE(spigpu);
  EXPECT_NE(spigpu.error().message.find("rec.gbtrace: a DMC-1 trace (metadata \"device_kind\": \"dmc1\"), not a spigpu one"),
            std::string::npos)
      << spigpu.error().message;
  // Played back (the recording's own name says nothing of its kind: its metadata does).
  auto sub = connect_to(socket_, "sub");
  ASSERT_TRUE(sub.subscribe(protocol::FrameFormat::RGB565, 0, 2000ms));
  const auto again = run_process(cli({"play", traces[0].string()}, socket_), 60s);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  auto f = sub.next_frame(5000ms);
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_TRUE(f->pixels == dmc1::frame_rows_rgb565(golden::golden_pixels("planes")));

  // `gpubridge trace`: the recording's words decoded, frame ends marked; converted to a .dmc1 stream
  // file holding the recorded words; any other output refused by name.
  const auto planes = golden::golden_stream("planes");
  const auto dump = run_process({GPUBRIDGE_CLI_PATH, "trace", "dump", traces[0].string()}, 30s);
  ASSERT_EQ(dump.exit_code, 0) << dump.err;
  EXPECT_NE(dump.out.find(traces[0].string() + ": DMC-1 recording\n"), std::string::npos) << dump.out.substr(0, 200);
  EXPECT_NE(dump.out.find(dmc1::describe(planes[0])), std::string::npos) << dump.out.substr(0, 400);
  EXPECT_NE(dump.out.find("-- end of frame 0\n"), std::string::npos);
  EXPECT_NE(dump.out.find(std::to_string(planes.size()) + " command words: 1 frames\n"), std::string::npos)
      << dump.out.substr(dump.out.size() - std::min<std::size_t>(dump.out.size(), 200));
  const auto out = dir_ / "planes-again.dmc1";
  const auto conv = run_process({GPUBRIDGE_CLI_PATH, "trace", "convert", traces[0].string(), out.string()}, 30s);
  ASSERT_EQ(conv.exit_code, 0) << conv.err;
  EXPECT_NE(conv.out.find("(DMC-1 dmc1 format, " + std::to_string(planes.size()) + " command words, 1 frames)"),
            std::string::npos)
      << conv.out;
  auto back = dmc1::load_stream(out);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(back->words == planes) << "the converted stream is not the recorded words";
  const auto refused = run_process({GPUBRIDGE_CLI_PATH, "trace", "convert", traces[0].string(), (dir_ / "x.gbt").string()}, 30s);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("holds DMC-1 command words, which convert to a DMC-1 stream file: name the output .dmc1 "
                             "(text) or .nfo (tinygpus lines)"),
            std::string::npos)
      << refused.err;
}

TEST_F(DaemonDmc1, MissingTexturesSayWhatToSet) {
  const auto r = run_process({GPUBRIDGED_PATH, "--check-config", "--backend", "dmc1", "--dmc1-textures",
                              (dir_ / "none.bin").string()}, 10s);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("none.bin is not a file (set --dmc1-textures / --dmc1-palette)"), std::string::npos) << r.err;
  const auto ok = run_process({GPUBRIDGED_PATH, "--check-config", "--backend", "dmc1"}, 10s);
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_NE(ok.out.find("the DMC-1 simulator (textures "), std::string::npos) << ok.out;
}

// A DMC-1 board whose port is not there: gpubridged does not start, and says which board, which
// port and what to do; --check-config describes the board without opening it; --mirror is refused.
TEST_F(DaemonDmc1, ABoardWithoutItsPortSaysWhatToDo) {
  fs::create_directories(dir_ / "boards");
  const auto tty = (dir_ / "ttyNONE").string();
  std::ofstream(dir_ / "boards" / "gone-dmc1.json")
      << R"({"name": "gone-dmc1", "description": "test: a DMC-1 SOC behind a port that is not there", "fpga": "iCE40 UP5K",
             "device_kind": "dmc1", "uart": {"vid": "0x0403", "pid": "0x6010", "interface": "B", "baud": 115200,
             "tty": ")" << tty << R"("}})";
  const auto r = run_process({GPUBRIDGED_PATH, "--listen", "unix:" + socket_, "--backend", "gone-dmc1", "--boards-dir",
                              dir_.string()}, 10s);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("gpubridged: board \"gone-dmc1\": " + tty + ": no such serial port; is the USB-UART plugged in?"),
            std::string::npos)
      << r.err;
  const auto check = run_process({GPUBRIDGED_PATH, "--check-config", "--backend", "gone-dmc1", "--boards-dir", dir_.string()}, 10s);
  EXPECT_EQ(check.exit_code, 0) << check.err;
  EXPECT_NE(check.out.find("board gone-dmc1 (DMC-1 over a USB-UART at 115200 baud, " + tty + ")"), std::string::npos) << check.out;
  const auto mirror = run_process(
      {GPUBRIDGED_PATH, "--check-config", "--backend", "gone-dmc1", "--boards-dir", dir_.string(), "--mirror"}, 10s);
  EXPECT_EQ(mirror.exit_code, 2);
  EXPECT_NE(mirror.err.find("\"gone-dmc1\" is a DMC-1 board"), std::string::npos) << mirror.err;
}

// `gpubridged --backend BOARD` for a DMC-1 UART board: the words reach the SOC's receiver through
// the port (the frame it draws is the golden one), the subscribers get the simulator's frame of
// the same words (also the golden one), and STATUS says whose frames they are.
TEST_F(DaemonDmc1, BoardBackendStreamsToItsPortAndShowsTheSimulatorsFrames) {
  golden::Pty pty;
  fs::create_directories(dir_ / "boards");
  std::ofstream(dir_ / "boards" / "pty-dmc1.json")
      << R"({"name": "pty-dmc1", "description": "test: a DMC-1 SOC behind a pseudo-terminal", "fpga": "iCE40 UP5K",
             "device_kind": "dmc1", "uart": {"vid": "0x0403", "pid": "0x6010", "interface": "B", "baud": 115200,
             "tty": ")" << pty.slave_path() << R"("}})";
  ASSERT_TRUE(daemon_.start({"--listen", "unix:" + socket_, "--backend", "pty-dmc1", "--boards-dir", dir_.string(),
                             "--log-level", "warn"}))
      << daemon_.error();
  auto watcher = connect_to(socket_, "watcher");
  EXPECT_EQ(watcher.session().device_kind, protocol::DeviceKind::Dmc1);
  auto s = watcher.status(2000ms);
  ASSERT_TRUE(s) << s.error().message;
  const auto status = nlohmann::json::parse(*s);
  EXPECT_EQ(status.at("device_kind"), "dmc1");
  EXPECT_EQ(status.at("backend"), "board");
  EXPECT_EQ(status.at("board"), "pty-dmc1");
  EXPECT_NE(status.at("bridge").get<std::string>().find(pty.slave_path()), std::string::npos) << status.dump();
  EXPECT_NE(status.value("frames_note", "").find("the simulator's frames"), std::string::npos) << status.dump();
  ASSERT_TRUE(watcher.subscribe(protocol::FrameFormat::RGB565, 0, 2000ms));

  // The board: the SOC's receiver model on the far end of the port, feeding its own DMC-1.
  auto gpu = dmc1::Device::create({}, golden::golden_textures(), golden::golden_palette());
  ASSERT_TRUE(gpu) << gpu.error().message;
  std::vector<std::uint16_t> board_frames;
  (*gpu)->set_frame_callback([&](const dmc1::Frame& f) { board_frames.insert(board_frames.end(), f.rgb565.begin(), f.rgb565.end()); });
  dmc1::SocReceiver receiver{[&](std::uint64_t w) { (*gpu)->submit(std::span(&w, 1)); }, nullptr};
  std::atomic<bool> played{false};
  ProcessResult play;
  std::thread host([&] {
    // 2,166 words at 115,200 baud take about 1.5 s on a real UART; a pty is not paced.
    play = run_process(cli({"play", (golden::kDataDir / "streams" / "walls.dmc1").string()}, socket_), 60s);
    played = true;
  });
  pty.read_until(played, [&](std::span<const std::uint8_t> b) { receiver.bytes(b); });
  host.join();
  ASSERT_EQ(play.exit_code, 0) << play.err;
  (*gpu)->flush();
  const auto words = golden::golden_stream("walls");
  EXPECT_EQ(receiver.stats().words, words.size());
  EXPECT_TRUE(board_frames == golden::golden_pixels("walls")) << "the board's frame is not the golden one";
  auto f = watcher.next_frame(5000ms);
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_TRUE(f->pixels == dmc1::frame_rows_rgb565(golden::golden_pixels("walls"))) << "the daemon's frame is not the golden one";
}

}  // namespace
}  // namespace gpubridge::test
