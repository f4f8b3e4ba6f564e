// End-to-end tests against a real gpubridged process on a Unix socket / loopback TCP.
#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <nlohmann/json.hpp>

#include "daemon_process.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/common/image.hpp"
#include "gpubridge/common/trace_files.hpp"
#include "gpubridge/protocol/frame.hpp"

namespace gpubridge::test {
namespace {

using namespace std::chrono_literals;
using protocol::LeaseMode;
using protocol::Reg;

class DaemonE2E : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = make_temp_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    socket_ = (dir_ / "d.sock").string();
  }
  void TearDown() override {
    daemon_.stop();
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  void start(std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"--listen", "unix:" + socket_, "--backend", "fake", "--log-level", "warn"};
    args.insert(args.end(), extra.begin(), extra.end());
    ASSERT_TRUE(daemon_.start(args)) << daemon_.error();
  }
  client::Client connect(const std::string& name, const std::string& address = "") {
    auto c = client::Client::connect(address.empty() ? "unix:" + socket_ : address, 2000ms);
    EXPECT_TRUE(c) << (c ? "" : c.error().message);
    auto h = c->handshake(name, "", 2000ms);
    EXPECT_TRUE(h) << (h ? "" : h.error().message);
    return std::move(*c);
  }
  std::vector<std::string> cli(std::vector<std::string> args) {
    args.insert(args.begin(), GPUBRIDGE_CLI_PATH);
    return args;
  }

  fs::path dir_;
  std::string socket_;
  Daemon daemon_;
};

std::vector<std::uint8_t> frames_of(std::initializer_list<protocol::Frame> fs) {
  std::vector<std::uint8_t> out;
  for (const auto& f : fs) protocol::append(out, f);
  return out;
}

TEST_F(DaemonE2E, SocketIsPrivateAndWelcomeDescribesDevice) {
  start();
  struct stat st{};
  ASSERT_EQ(::stat(socket_.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  auto c = connect("welcome");
  const auto j = nlohmann::json::parse(c.session().device_json);
  EXPECT_EQ(j["backend"], "fake");
  EXPECT_GT(c.session().session_id, 0u);
}

TEST_F(DaemonE2E, SecondDaemonOnTheSameSocketIsRefused) {
  start();
  const auto r = run_process({GPUBRIDGED_PATH, "--listen", "unix:" + socket_, "--backend", "fake"}, 5s);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("another gpubridged"), std::string::npos) << r.err;
  // The first daemon still serves.
  auto c = connect("still-there");
  EXPECT_TRUE(c.ping(1000ms));
}

TEST_F(DaemonE2E, StaleSocketFileIsReplaced) {
  { std::ofstream(socket_) << "stale"; }
  start();
  auto c = connect("after-stale");
  EXPECT_TRUE(c.ping(1000ms));
}

TEST_F(DaemonE2E, RegisterWritesReadBackThroughTheLease) {
  start();
  auto c = connect("writer");
  // Without the lease, drawing is refused.
  const auto w = frames_of({protocol::write_frame(Reg::CLEAR_COLOR, 0x11223344)});
  ASSERT_TRUE(c.write_frames(protocol::FrameView{w}, 1000ms));
  auto fenced = c.fence(1000ms);
  ASSERT_FALSE(fenced);
  EXPECT_TRUE(client::is_protocol_error(fenced.error(), protocol::ErrorCode::NoLease)) << fenced.error().message;

  ASSERT_TRUE(c.acquire_lease(LeaseMode::FailIfBusy, 1000ms));
  ASSERT_TRUE(c.write_frames(protocol::FrameView{w}, 1000ms));
  ASSERT_TRUE(c.fence(1000ms));
  auto v = c.read_register(protocol::index_of(Reg::CLEAR_COLOR), 1000ms);
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_EQ(*v, 0x11223344u);
}

TEST_F(DaemonE2E, TwoClientsCompeteForTheLease) {
  start();
  auto a = connect("a");
  auto b = connect("b");
  ASSERT_TRUE(a.acquire_lease(LeaseMode::Wait, 1000ms));
  // Fail-if-busy gets BUSY at once.
  auto busy = b.acquire_lease(LeaseMode::FailIfBusy, 1000ms);
  ASSERT_FALSE(busy);
  EXPECT_TRUE(client::is_protocol_error(busy.error(), protocol::ErrorCode::Busy)) << busy.error().message;
  // Wait mode: b is granted only after a releases.
  std::atomic<bool> released{false};
  auto waiter = std::async(std::launch::async, [&] {
    auto r = b.acquire_lease(LeaseMode::Wait, 5000ms);
    return std::make_pair(static_cast<bool>(r), released.load());
  });
  EXPECT_EQ(waiter.wait_for(300ms), std::future_status::timeout);  // still waiting while a holds it
  // a leaves the device in some state; the release must reset it before b draws.
  const auto w = frames_of({protocol::write_frame(Reg::CLEAR_COLOR, 0xDEADBEEF)});
  ASSERT_TRUE(a.write_frames(protocol::FrameView{w}, 1000ms));
  ASSERT_TRUE(a.fence(1000ms));
  released = true;
  ASSERT_TRUE(a.release_lease(1000ms));
  const auto [granted, after_release] = waiter.get();
  EXPECT_TRUE(granted);
  EXPECT_TRUE(after_release);
  auto v = b.read_register(protocol::index_of(Reg::CLEAR_COLOR), 1000ms);
  ASSERT_TRUE(v);
  EXPECT_EQ(*v, protocol::describe(Reg::CLEAR_COLOR).reset);
  // The status shows b as the holder.
  auto s = b.status(1000ms);
  ASSERT_TRUE(s);
  EXPECT_EQ(nlohmann::json::parse(*s)["lease"]["name"], "b");
}

TEST_F(DaemonE2E, LeaseIsReleasedWhenTheHolderDisconnects) {
  start();
  auto b = connect("b");
  {
    auto a = connect("a");
    ASSERT_TRUE(a.acquire_lease(LeaseMode::Wait, 1000ms));
  }  // a's socket closes without BYE
  EXPECT_TRUE(b.acquire_lease(LeaseMode::Wait, 3000ms));
}

TEST_F(DaemonE2E, UploadAndReadbackRoundTripThroughTheCli) {
  start();
  std::vector<std::uint8_t> data(200000);
  std::mt19937 rng(7);
  for (auto& b : data) b = static_cast<std::uint8_t>(rng());
  const auto in = (dir_ / "in.bin").string(), out = (dir_ / "out.bin").string();
  std::ofstream(in, std::ios::binary).write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
  // Upload and readback run as separate clients: memory survives the lease reset between them.
  auto up = run_process(cli({"upload", "0x1000", in, "--connect", "unix:" + socket_}));
  ASSERT_EQ(up.exit_code, 0) << up.err;
  auto rb = run_process(cli({"readback", "0x1000", std::to_string(data.size()), "--out", out, "--connect", "unix:" + socket_, "--json"}));
  ASSERT_EQ(rb.exit_code, 0) << rb.err;
  EXPECT_EQ(nlohmann::json::parse(rb.out)["bytes"], data.size());
  std::ifstream f(out, std::ios::binary);
  std::vector<std::uint8_t> back((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_EQ(back, data);
  // Beyond the fake device's 1 MiB memory: a one-line error, exit 1.
  auto bad = run_process(cli({"readback", "0xFFF00", "0x1000", "--out", out, "--connect", "unix:" + socket_}));
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("RANGE"), std::string::npos) << bad.err;
}

TEST_F(DaemonE2E, CliRegStatusAndErrors) {
  start();
  auto wr = run_process(cli({"reg", "write", "CLEAR_COLOR", "0x55667788", "--connect", "unix:" + socket_}));
  ASSERT_EQ(wr.exit_code, 0) << wr.err;
  // The write's client disconnected, which reset the device: the value is back to reset.
  auto rd = run_process(cli({"reg", "read", "ID", "--connect", "unix:" + socket_, "--json"}));
  ASSERT_EQ(rd.exit_code, 0) << rd.err;
  EXPECT_EQ(nlohmann::json::parse(rd.out)["register"], "ID");
  auto st = run_process(cli({"status", "--json", "--connect", "unix:" + socket_}));
  ASSERT_EQ(st.exit_code, 0) << st.err;
  const auto j = nlohmann::json::parse(st.out);
  EXPECT_EQ(j["backend"], "fake");
  EXPECT_EQ(j["client_count"], 1);  // the status client itself
  auto usage = run_process(cli({"reg", "read", "NO_SUCH_REG", "--connect", "unix:" + socket_}));
  EXPECT_EQ(usage.exit_code, 2);
  auto missing = run_process(cli({"status", "--connect", "unix:" + (dir_ / "nope.sock").string()}));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("is gpubridged running?"), std::string::npos) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
}

TEST_F(DaemonE2E, ConnectionCapRefusesExplicitly) {
  start({"--max-clients", "2"});
  auto a = connect("a");
  auto b = connect("b");
  auto c = client::Client::connect("unix:" + socket_, 1000ms);
  ASSERT_TRUE(c);
  auto h = c->handshake("c", "", 2000ms);
  ASSERT_FALSE(h);
  EXPECT_TRUE(client::is_protocol_error(h.error(), protocol::ErrorCode::ServerFull)) << h.error().message;
  // After one leaves, a new client is admitted.
  b.close();
  // The daemon notices b's departure asynchronously; a new client is admitted once it has.
  bool admitted = false;
  for (int i = 0; i < 100 && !admitted; ++i) {
    auto d = client::Client::connect("unix:" + socket_, 1000ms);
    ASSERT_TRUE(d);
    auto hd = d->handshake("d", "", 2000ms);
    if (hd) {
      admitted = d->ping(1000ms).ok();
    } else {
      EXPECT_TRUE(client::is_protocol_error(hd.error(), protocol::ErrorCode::ServerFull)) << hd.error().message;
      std::this_thread::sleep_for(20ms);
    }
  }
  EXPECT_TRUE(admitted);
}

TEST_F(DaemonE2E, SigtermDuringAStreamExitsCleanlyWithinTwoSeconds) {
  start();
  auto c = connect("streamer");
  ASSERT_TRUE(c.acquire_lease(LeaseMode::Wait, 1000ms));
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> sent{0};
  auto streamer = std::async(std::launch::async, [&] {
    std::vector<std::uint8_t> batch;
    for (int i = 0; i < 4096; ++i) protocol::append(batch, protocol::write_frame(Reg::COLOR, static_cast<std::uint64_t>(i)));
    while (!stop) {
      if (!c.write_frames(protocol::FrameView{batch}, 1000ms)) return;
      sent += 4096;
    }
  });
  while (sent < 100000) std::this_thread::sleep_for(1ms);
  const auto t0 = std::chrono::steady_clock::now();
  const int code = daemon_.terminate(5s);
  const auto took = std::chrono::steady_clock::now() - t0;
  stop = true;
  streamer.get();
  EXPECT_EQ(code, 0) << daemon_.error();
  EXPECT_LT(took, 2s);
  EXPECT_FALSE(fs::exists(socket_));
  EXPECT_FALSE(fs::exists(socket_ + ".lock"));
}

TEST_F(DaemonE2E, NonLoopbackTcpNeedsAToken) {
  auto r = run_process({GPUBRIDGED_PATH, "--listen", "tcp:0.0.0.0:0", "--backend", "fake"}, 5s);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("token"), std::string::npos) << r.err;

  start({"--listen", "tcp:0.0.0.0:0", "--token", "s3cret", "--tls-dir", (dir_ / "tls").string()});
  ASSERT_EQ(daemon_.endpoints().size(), 2u);
  const auto port = daemon_.endpoints()[1].substr(daemon_.endpoints()[1].rfind(':') + 1);
  // A listener other machines can reach takes TLS only (issue 21): the token never crosses in clear.
  ::setenv("GPUBRIDGE_KNOWN_HOSTS", (dir_ / "known_hosts").c_str(), 1);
  {
    auto c = client::Client::connect("tcp:127.0.0.1:" + port, 1000ms);
    ASSERT_TRUE(c) << c.error().message;
    auto h = c->handshake("plain", "s3cret", 2000ms);
    ASSERT_FALSE(h);
    EXPECT_TRUE(client::is_protocol_error(h.error(), protocol::ErrorCode::AuthFailed)) << h.error().message;
    EXPECT_NE(h.error().message.find("takes TLS only"), std::string::npos) << h.error().message;
  }
  const std::string addr = "tls:127.0.0.1:" + port;
  {
    auto c = client::Client::connect(addr, 1000ms);
    ASSERT_TRUE(c) << c.error().message;
    auto h = c->handshake("intruder", "wrong", 2000ms);
    ASSERT_FALSE(h);
    EXPECT_TRUE(client::is_protocol_error(h.error(), protocol::ErrorCode::AuthFailed)) << h.error().message;
    EXPECT_NE(h.error().message.find("token rejected"), std::string::npos) << h.error().message;
  }
  {
    auto c = client::Client::connect(addr, 1000ms);
    ASSERT_TRUE(c) << c.error().message;
    auto h = c->handshake("friend", "s3cret", 2000ms);
    ASSERT_TRUE(h) << h.error().message;
    EXPECT_TRUE(c->ping(1000ms));
  }
  ::unsetenv("GPUBRIDGE_KNOWN_HOSTS");
  // The Unix socket needs no token: file permissions guard it.
  auto u = connect("local");
  EXPECT_TRUE(u.ping(1000ms));
}

TEST_F(DaemonE2E, BadConfigNamesTheKey) {
  const auto cfg = (dir_ / "bad.json").string();
  std::ofstream(cfg) << R"({"limits": {"max_clients": "ten"}})";
  auto r = run_process({GPUBRIDGED_PATH, "--config", cfg}, 5s);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(cfg + ": limits.max_clients: expected an integer 1..4096, got \"ten\""), std::string::npos) << r.err;
}

// --check-config: names what would be served without opening it, prints a configuration that
// --config accepts, and fails with the same message the daemon would give.
TEST_F(DaemonE2E, CheckConfigDescribesTheBackendAndPrintsALoadableConfiguration) {
  auto ok = run_process({GPUBRIDGED_PATH, "--check-config", "--json", "--backend", "icebreaker", "--mirror",
                         "--listen", "unix:" + (dir_ / "c.sock").string(), "--max-clients", "7"}, 5s);
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_FALSE(fs::exists(dir_ / "c.sock"));  // nothing was started
  const auto j = nlohmann::json::parse(ok.out);
  EXPECT_TRUE(j.at("ok").get<bool>());
  const auto backend = j.at("backend").get<std::string>();
  EXPECT_NE(backend.find("board icebreaker (ft2232h) from "), std::string::npos) << backend;
  EXPECT_NE(backend.find("mirrored by the simulator"), std::string::npos) << backend;
  EXPECT_EQ(j.at("config").at("limits").at("max_clients"), 7);
  const auto file = (dir_ / "effective.json").string();
  std::ofstream(file) << j.at("config").dump(2);
  auto again = run_process({GPUBRIDGED_PATH, "--config", file, "--check-config"}, 5s);
  EXPECT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("configuration OK (" + file + ")"), std::string::npos) << again.out;
  EXPECT_NE(again.out.find("\"max_clients\": 7"), std::string::npos) << again.out;

  auto typo = run_process({GPUBRIDGED_PATH, "--check-config", "--json", "--backend", "icebreakr"}, 5s);
  EXPECT_EQ(typo.exit_code, 2);
  const auto e = nlohmann::json::parse(typo.out);
  EXPECT_FALSE(e.at("ok").get<bool>());
  EXPECT_NE(e.at("error").get<std::string>().find("no board profile named \"icebreakr\""), std::string::npos) << typo.out;
  EXPECT_NE(typo.err.find("known: "), std::string::npos) << typo.err;
  auto mirror_sim = run_process({GPUBRIDGED_PATH, "--check-config", "--backend", "sim", "--mirror"}, 5s);
  EXPECT_EQ(mirror_sim.exit_code, 2);
  EXPECT_NE(mirror_sim.err.find("--mirror needs a board backend"), std::string::npos) << mirror_sim.err;
  auto small_queue = run_process({GPUBRIDGED_PATH, "--check-config", "--queue-bytes", "100"}, 5s);
  EXPECT_EQ(small_queue.exit_code, 2);
  EXPECT_NE(small_queue.err.find("limits.queue_bytes (--queue-bytes): expected an integer 1048576.."), std::string::npos)
      << small_queue.err;
  auto level = run_process({GPUBRIDGED_PATH, "--log-level", "verbose"}, 5s);
  EXPECT_EQ(level.exit_code, 2);
  EXPECT_NE(level.err.find("--log-level"), std::string::npos) << level.err;
}

TEST_F(DaemonE2E, SubscriberGetsEveryFrameAndScreenshotWritesIt) {
  start();
  auto sub = connect("sub");
  ASSERT_TRUE(sub.subscribe(protocol::FrameFormat::RGBA8888, 0, 1000ms));
  auto shot = std::async(std::launch::async, [&] {
    return run_process(cli({"screenshot", "--out", (dir_ / "shot.png").string(), "--connect", "unix:" + socket_, "--json"}));
  });
  // Wait until the screenshot client has subscribed (2 subscribers in the status).
  for (int i = 0; i < 200; ++i) {
    auto s = sub.status(1000ms);
    ASSERT_TRUE(s);
    int subs = 0;
    const auto status = nlohmann::json::parse(*s);  // a named object: range-for over a temporary's member dangles
    for (const auto& cl : status["clients"]) subs += cl["subscribed"].get<bool>();
    if (subs == 2) break;
    ASSERT_LT(i, 199) << "the screenshot client never subscribed";
    std::this_thread::sleep_for(10ms);
  }
  auto drawer = connect("drawer");
  ASSERT_TRUE(drawer.acquire_lease(LeaseMode::Wait, 1000ms));
  const auto w = frames_of({protocol::write_frame(Reg::CLEAR_COLOR, 0x10203040), protocol::write_frame(Reg::FB_DISPLAY, 0)});
  ASSERT_TRUE(drawer.write_frames(protocol::FrameView{w}, 1000ms));
  ASSERT_TRUE(drawer.fence(1000ms));
  auto f = sub.next_frame(2000ms);
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->pixels.size(), std::size_t{f->width} * f->height * 4);
  EXPECT_EQ(f->pixels[0], 0x10);
  EXPECT_EQ(f->pixels[1], 0x20);
  EXPECT_EQ(f->pixels[2], 0x30);
  const auto r = shot.get();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto img = load_png(dir_ / "shot.png");
  ASSERT_TRUE(img) << img.error().message;
  EXPECT_EQ(img->width, f->width);
  EXPECT_EQ(img->rgba, f->pixels);
}

// --connect and --token are global options (issue 15): accepted before the command, as --json and
// --log-level are, and after it (also after a nested command); refused for commands that do not
// talk to the daemon instead of being ignored.
TEST_F(DaemonE2E, ConnectIsAGlobalOptionBeforeOrAfterTheCommand) {
  start();
  const std::string at = "unix:" + socket_;
  for (const auto& args : std::vector<std::vector<std::string>>{{"--connect", at, "status"},
                                                                 {"status", "--connect", at},
                                                                 {"--json", "--connect", at, "status"},
                                                                 {"--connect", at, "reg", "read", "ID"},
                                                                 {"reg", "read", "ID", "--connect", at},
                                                                 {"--connect", at, "--token", "unused", "status"}}) {
    const auto r = run_process(cli(args));
    std::string line;
    for (const auto& a : args) line += a + " ";
    EXPECT_EQ(r.exit_code, 0) << line << ": " << r.err;
    EXPECT_EQ(r.err.find("not expected"), std::string::npos) << line << ": " << r.err;
  }
  const auto local = run_process(cli({"--connect", at, "regs"}));
  EXPECT_EQ(local.exit_code, 2);
  EXPECT_NE(local.err.find("--connect and --token only apply to the commands that talk to gpubridged (status, "
                            "play, screenshot, reg read, reg write, upload, readback)"),
            std::string::npos)
      << local.err;
}

// `gpubridge screenshot` says what happened when no frame comes (issue 15): nothing drawing,
// the daemon going away, or (daemon_board_test) frames scanned out that carry no picture.
TEST_F(DaemonE2E, ScreenshotWithNothingDrawingSaysSo) {
  start();
  auto drawer = connect("drawer");
  ASSERT_TRUE(drawer.acquire_lease(LeaseMode::Wait, 1000ms));
  const auto w = frames_of({protocol::write_frame(Reg::FB_DISPLAY, 0)});
  ASSERT_TRUE(drawer.write_frames(protocol::FrameView{w}, 1000ms));  // one frame before: counted, not new
  ASSERT_TRUE(drawer.fence(1000ms));
  const auto r = run_process(cli({"screenshot", "--out", (dir_ / "none.png").string(), "--timeout", "300",
                                  "--connect", "unix:" + socket_}));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no frame within 0.3 s: nothing is drawing (the daemon scanned out no frame while we waited; "
                       "1 since it started)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "none.png"));
}

TEST_F(DaemonE2E, ScreenshotWhenTheDaemonStopsSaysSo) {
  start();
  auto shot = std::async(std::launch::async, [&] {
    return run_process(cli({"screenshot", "--out", (dir_ / "none.png").string(), "--connect", "unix:" + socket_}));
  });
  auto watcher = connect("watcher");
  bool subscribed = false;
  for (int i = 0; i < 500 && !subscribed; ++i) {
    auto st = watcher.status(1000ms);
    ASSERT_TRUE(st);
    const auto status = nlohmann::json::parse(*st);
    for (const auto& cl : status["clients"]) subscribed = subscribed || cl["subscribed"].get<bool>();
    if (!subscribed) std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(subscribed) << "the screenshot client never subscribed";
  watcher.close();
  EXPECT_EQ(daemon_.terminate(), 0);
  const auto r = shot.get();
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("gpubridge screenshot: gpubridged shut down before a frame arrived (SHUTTING_DOWN"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("is anything drawing"), std::string::npos) << r.err;
}

// A rate-limited subscriber (max_fps 2) skips frames that come too fast, but the newest one is
// delivered when its interval ends: the last frame of an animation is never lost.
TEST_F(DaemonE2E, RateLimitedSubscriberStillGetsTheLastFrame) {
  start();
  auto sub = connect("slow-viewer");
  ASSERT_TRUE(sub.subscribe(protocol::FrameFormat::RGBA8888, 2, 1000ms));
  auto drawer = connect("drawer");
  ASSERT_TRUE(drawer.acquire_lease(LeaseMode::Wait, 1000ms));
  for (std::uint32_t i = 1; i <= 5; ++i) {  // five swaps well inside one 500 ms interval
    const auto w = frames_of({protocol::write_frame(Reg::CLEAR_COLOR, (i << 24) | 0xFF),
                              protocol::write_frame(Reg::FB_DISPLAY, 0)});
    ASSERT_TRUE(drawer.write_frames(protocol::FrameView{w}, 1000ms));
  }
  ASSERT_TRUE(drawer.fence(1000ms));
  auto first = sub.next_frame(2000ms);
  ASSERT_TRUE(first) << first.error().message;
  EXPECT_EQ(first->pixels[0], 1);  // the first swap goes out at once
  auto last = sub.next_frame(2000ms);
  ASSERT_TRUE(last) << "the newest held-back frame never arrived: " << last.error().message;
  EXPECT_EQ(last->pixels[0], 5);  // frames 2..4 were superseded, 5 arrived when the interval ended
  EXPECT_FALSE(sub.next_frame(700ms)) << "only two frames may be sent for a burst inside one interval";
}

}  // namespace
}  // namespace gpubridge::test

namespace gpubridge::test {
namespace {

// play TRACE through the daemon (simulator backend) + screenshot == gpubridge render TRACE, pixel for pixel.
TEST(DaemonSim, PlayedTraceScreenshotEqualsInProcessRender) {
  const auto dir = make_temp_dir("sim-play");
  const auto socket = (dir / "d.sock").string();
  const std::string trace = std::string(GPUBRIDGE_TEST_DATA) + "/triangle.trace";
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", "unix:" + socket, "--backend", "sim", "--log-level", "warn"})) << daemon.error();
  auto shot = std::async(std::launch::async, [&] {
    return run_process({GPUBRIDGE_CLI_PATH, "screenshot", "--out", (dir / "shot.png").string(), "--connect", "unix:" + socket});
  });
  // Wait until the screenshot client is subscribed before drawing.
  auto watcher = client::Client::connect("unix:" + socket, 2000ms);
  ASSERT_TRUE(watcher);
  ASSERT_TRUE(watcher->handshake("watcher", "", 2000ms));
  bool subscribed = false;
  for (int i = 0; i < 500 && !subscribed; ++i) {
    auto s = watcher->status(1000ms);
    ASSERT_TRUE(s);
    const auto status = nlohmann::json::parse(*s);  // a named object: range-for over a temporary's member dangles
    for (const auto& cl : status["clients"]) subscribed = subscribed || cl["subscribed"].get<bool>();
    if (!subscribed) std::this_thread::sleep_for(10ms);
  }
  if (!subscribed) {
    const auto r = shot.get();
    FAIL() << "screenshot never subscribed; it exited " << r.exit_code << ": " << r.err << r.out << " status "
           << *watcher->status(1000ms);
  }
  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", trace, "--connect", "unix:" + socket});
  ASSERT_EQ(play.exit_code, 0) << play.err;
  const auto s = shot.get();
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const auto render = run_process({GPUBRIDGE_CLI_PATH, "render", trace, "--out", (dir / "ref.png").string()});
  ASSERT_EQ(render.exit_code, 0) << render.err;
  auto got = load_png(dir / "shot.png");
  auto want = load_png(dir / "ref.png");
  ASSERT_TRUE(got) << got.error().message;
  ASSERT_TRUE(want) << want.error().message;
  ASSERT_EQ(got->width, 320u);
  ASSERT_EQ(got->height, 240u);
  // The picture is not just the clear colour (the triangle is there) ...
  EXPECT_NE(std::vector<std::uint8_t>(got->pixel(160, 150), got->pixel(160, 150) + 4),
            std::vector<std::uint8_t>(got->pixel(2, 2), got->pixel(2, 2) + 4));
  // ... and the daemon's frame equals the in-process render exactly.
  EXPECT_TRUE(got->rgba == want->rgba);
  daemon.stop();
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace gpubridge::test

namespace gpubridge::test {
namespace {

// --record DIR: the session's stream is written as a binary trace holding exactly what was played.
TEST(DaemonRecord, RecordedTraceReplaysThePlayedCommands) {
  const auto dir = make_temp_dir("record");
  const auto socket = (dir / "d.sock").string();
  const std::string trace = std::string(GPUBRIDGE_TEST_DATA) + "/triangle.trace";
  Daemon daemon;
  ASSERT_TRUE(daemon.start({"--listen", "unix:" + socket, "--backend", "fake", "--record", (dir / "rec").string()}))
      << daemon.error();
  const auto play = run_process({GPUBRIDGE_CLI_PATH, "play", trace, "--connect", "unix:" + socket});
  ASSERT_EQ(play.exit_code, 0) << play.err;
  ASSERT_EQ(daemon.terminate(), 0);
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir / "rec")) files.push_back(e.path());
  ASSERT_EQ(files.size(), 1u);
  EXPECT_NE(files[0].filename().string().find("gpubridge_play"), std::string::npos) << files[0];
  auto recorded = load_trace(files[0]);
  ASSERT_TRUE(recorded) << recorded.error().message;
  auto original = load_trace(trace);
  ASSERT_TRUE(original) << original.error().message;
  // play sends the trace's commands, then one FENCE to wait for completion.
  ASSERT_EQ(recorded->commands.size(), original->commands.size() + 1);
  for (std::size_t i = 0; i < original->commands.size(); ++i)
    EXPECT_TRUE(recorded->commands[i].command == original->commands[i].command) << "command " << i;
  EXPECT_TRUE(std::holds_alternative<protocol::FenceCmd>(recorded->commands.back().command));
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace gpubridge::test
