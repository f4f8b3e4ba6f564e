// The DMC-1 example client live through gpubridged (docs/dmc1.md "Example client"), the way the
// README runs it: `gpubridged --backend dmc1` on the default socket, `gpubridge-dmc1-demo stream`
// with no address; a subscriber's frames are the in-process simulator's for the same frames of the
// camera path, bit for bit. And the errors: a daemon serving the other device kind, no daemon at all.
#include <algorithm>
#include <future>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../dmc1/golden_data.hpp"
#include "daemon_fixture.hpp"
#include "daemon_process.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/common/image.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/examples/dmc1_level.hpp"

namespace gpubridge::test {
namespace {

using namespace std::chrono_literals;
namespace golden = dmc1::test;
namespace level = examples::dmc1_level;

// A daemon on the default socket: XDG_RUNTIME_DIR is the test's own run/ directory, for the daemon
// and every program the test runs.
class DaemonDmc1Client : public DaemonDirTest {
 protected:
  void SetUp() override {
    DaemonDirTest::SetUp();
    fs::create_directories(dir_ / "run");
    env_ = {"XDG_RUNTIME_DIR=" + (dir_ / "run").string(), "GPUBRIDGE_ADDRESS=", "GPUBRIDGE_TOKEN="};
  }
  std::string default_socket() const { return "unix:" + (dir_ / "run" / "gpubridge" / "gpubridge.sock").string(); }
  ProcessResult demo(std::vector<std::string> args) {
    args.insert(args.begin(), GPUBRIDGE_DMC1_DEMO_PATH);
    return run_process(args, 60s, env_);
  }
  // The in-process simulator fed the frames first .. first + count - 1 of the path from reset: each
  // frame's RGB565 rows as the daemon sends them.
  static std::vector<std::vector<std::uint8_t>> render_in_process(unsigned first, unsigned count) {
    auto dev = dmc1::Device::create({}, golden::golden_textures(), golden::golden_palette());
    if (!dev) throw std::runtime_error(dev.error().message);
    std::vector<std::vector<std::uint8_t>> frames;
    (*dev)->set_frame_callback([&](const dmc1::Frame& f) { frames.push_back(dmc1::frame_rows_rgb565(f.rgb565)); });
    for (unsigned n = first; n < first + count; ++n) (*dev)->submit(level::lap_frame_commands(level::hall(), n, level::kPathFrames));
    return frames;
  }
  std::vector<std::string> env_;
};

// The moving camera: eight frames streamed as fast as the daemon takes them; every frame the
// subscriber receives is the in-process render of the same frame of the same sequence (the DMC-1
// keeps state across frames: column 0 after reset is black, later it is not), and the last arrives.
TEST_F(DaemonDmc1Client, StreamedLevelReachesASubscriberBitForBit) {
  ASSERT_TRUE(daemon_.start({"--backend", "dmc1", "--log-level", "warn"}, env_)) << daemon_.error();
  auto sub = client::Client::connect(default_socket(), 2000ms);
  ASSERT_TRUE(sub) << sub.error().message;
  ASSERT_TRUE(sub->handshake("subscriber", "", 2000ms));
  ASSERT_TRUE(sub->subscribe(protocol::FrameFormat::RGB565, 0, 2000ms));
  constexpr unsigned kFirst = 5, kFrames = 8;
  const auto r = demo({"stream", "--first", std::to_string(kFirst), "--frames", std::to_string(kFrames), "--fps", "0", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary.at("frames"), kFrames);
  EXPECT_EQ(summary.at("address"), default_socket());
  EXPECT_EQ(summary.at("interrupted"), false);
  std::uint64_t commands = 0;
  for (unsigned n = kFirst; n < kFirst + kFrames; ++n) commands += level::lap_frame_commands(level::hall(), n, level::kPathFrames).size();
  EXPECT_EQ(summary.at("commands"), commands);
  EXPECT_GT(summary.at("bytes").get<std::uint64_t>(), 8 * commands) << "DMC1_WORDS carry 8 bytes per command plus headers";
  EXPECT_GT(summary.at("fps").get<double>(), 0);

  const auto want = render_in_process(kFirst, kFrames);
  ASSERT_EQ(want.size(), kFrames);
  EXPECT_FALSE(want[0] == dmc1::frame_rows_rgb565(std::vector<std::uint16_t>(dmc1::kFramePixels)))
      << "the level drew nothing";
  unsigned received = 0;
  std::uint32_t last = 0;
  while (last + 1 < kFrames) {
    auto f = sub->next_frame(10000ms);
    ASSERT_TRUE(f) << "after " << received << " frame(s): " << f.error().message;
    ASSERT_LT(f->number, kFrames) << "a fresh daemon numbers its frames from 0";
    EXPECT_EQ(f->width, dmc1::kColumns);
    EXPECT_EQ(f->height, dmc1::kRows);
    EXPECT_TRUE(f->pixels == want[f->number]) << "frame " << f->number << " (path frame " << kFirst + f->number
                                               << ") differs from the in-process render";
    last = f->number;
    ++received;
  }
  EXPECT_GE(received, 1u);
}

// A fresh daemon's first frame is the chip's first frame after reset: path frame 12 streamed alone
// is the committed golden examples/dmc1/golden/level-12.png, as `gpubridge screenshot` saves it.
TEST_F(DaemonDmc1Client, AFrameStreamedAloneIsItsGolden) {
  ASSERT_TRUE(daemon_.start({"--backend", "dmc1", "--log-level", "warn"}, env_)) << daemon_.error();
  const auto png = dir_ / "shot.png";
  auto shot = std::async(std::launch::async, [&] {
    return run_process({GPUBRIDGE_CLI_PATH, "screenshot", "--out", png.string()}, 60s, env_);
  });
  // The screenshot must be subscribed before the frame: wait until the daemon lists it.
  auto watcher = client::Client::connect(default_socket(), 2000ms);
  ASSERT_TRUE(watcher) << watcher.error().message;
  ASSERT_TRUE(watcher->handshake("watcher", "", 2000ms));
  bool subscribed = false;
  for (int i = 0; i < 1000 && !subscribed; ++i) {
    auto s = watcher->status(2000ms);
    ASSERT_TRUE(s) << s.error().message;
    const auto status = nlohmann::json::parse(*s);
    for (const auto& c : status.at("clients")) subscribed |= c.at("subscribed").get<bool>();
    if (!subscribed) std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(subscribed) << "gpubridge screenshot never subscribed";
  const auto r = demo({"stream", "--first", "12", "--frames", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("streamed 1 frame(s) of the DMC-1 level to " + default_socket()), std::string::npos) << r.out;
  const auto s = shot.get();
  ASSERT_EQ(s.exit_code, 0) << s.err;
  auto got = load_png(png);
  ASSERT_TRUE(got) << got.error().message;
  auto want = load_png(fs::path(GPUBRIDGE_DMC1_GOLDEN_DIR) / "level-12.png");
  ASSERT_TRUE(want) << want.error().message;
  EXPECT_TRUE(*got == *want) << "the daemon's frame differs from examples/dmc1/golden/level-12.png";
}

// A daemon serving spigpu: one clear line before the lease (what, where, what to start instead),
// exit 1; and the daemon goes on serving.
TEST_F(DaemonDmc1Client, ADaemonOfTheOtherKindIsNamed) {
  ASSERT_TRUE(daemon_.start({"--backend", "sim", "--log-level", "warn"}, env_)) << daemon_.error();
  const auto r = demo({"stream", "--frames", "2"});
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_EQ(r.err, "gpubridge-dmc1-demo: the DMC-1 example level is a DMC-1 stream, but the daemon at " + default_socket() +
                       " serves a spigpu (`gpubridge status` shows its device kind); start gpubridged --backend dmc1 "
                       "(or a DMC-1 board: --backend icebreaker-dmc1) for it\n");
  EXPECT_EQ(run_process({GPUBRIDGE_CLI_PATH, "status"}, 10s, env_).exit_code, 0) << "the daemon stopped serving";
}

TEST_F(DaemonDmc1Client, NoDaemonSaysWhatToStart) {
  const auto r = demo({"stream"});
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.err.find("cannot connect to " + default_socket()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("is gpubridged running?"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("gpubridged --backend dmc1"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// A frame rate that is no rate (NaN, Inf, one so small the n-th frame's due time overflows the
// clock, negative) is refused before connecting, by the demo and by `gpubridge play` alike (the
// client library's check_pace_options; CLI11's Range let NaN through to a float-to-integer cast).
TEST_F(DaemonDmc1Client, AFrameRateThatIsNoRateIsRefused) {
  const fs::path stream = dir_ / "one.dmc1";
  ASSERT_EQ(demo({"write", "--frames", "1", "--out", stream.string()}).exit_code, 0);
  for (const std::string fps : {"nan", "inf", "1e-300", "-1", "1e6"}) {
    const auto r = demo({"stream", "--fps", fps});
    EXPECT_EQ(r.exit_code, 2) << fps << ": " << r.err;
    EXPECT_NE(r.err.find("--fps must be 0 (unpaced) or 0.001000 .. 100000 frames per second"), std::string::npos) << fps << ": " << r.err;
    EXPECT_EQ(r.err.find("cannot connect"), std::string::npos) << fps << ": refused only after trying the daemon";
    const auto p = run_process({GPUBRIDGE_CLI_PATH, "play", "--fps", fps, stream.string()}, 10s, env_);
    EXPECT_EQ(p.exit_code, 1) << fps << ": " << p.err;
    EXPECT_NE(p.err.find("--fps must be 0 (unpaced)"), std::string::npos) << fps << ": " << p.err;
  }
}

}  // namespace
}  // namespace gpubridge::test
