// Misbehaving clients next to a good one, and a subscriber that never reads.
#include <gtest/gtest.h>

#include <future>
#include <random>

#include <nlohmann/json.hpp>

#include "daemon_fixture.hpp"
#include "daemon_process.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::test {
namespace {

using namespace std::chrono_literals;
using protocol::Reg;

std::vector<std::uint8_t> hello_bytes(const std::string& name) {
  return protocol::encode(protocol::Message{1, protocol::Hello{protocol::kSocketVersion, name, ""}});
}

// What a good client sees: memory it uploaded and register values, read back.
struct GoodResult {
  std::vector<std::uint8_t> memory;
  std::uint64_t color = 0;
  bool ok = false;
  std::string error;
};

GoodResult failed(std::string why) {
  GoodResult g;
  g.error = std::move(why);
  return g;
}

GoodResult run_good_client(const std::string& socket, const std::vector<std::uint8_t>& pattern) {
  GoodResult g;
  auto c = client::Client::connect("unix:" + socket, 2000ms);
  if (!c) return failed(c.error().message);
  if (auto h = c->handshake("good", "", 2000ms); !h) return failed(h.error().message);
  if (auto r = c->acquire_lease(protocol::LeaseMode::Wait, 5000ms); !r) return failed(r.error().message);
  std::vector<std::uint8_t> frames;
  for (std::uint64_t i = 0; i < 20000; ++i) protocol::append(frames, protocol::write_frame(Reg::CLEAR_COLOR, i * 0x9E3779B9ull));
  if (auto r = c->write_frames(protocol::FrameView{frames}, 5000ms); !r) return failed(r.error().message);
  if (auto r = c->upload(0x100, pattern, {}, 5000ms); !r) return failed(r.error().message);
  auto mem = c->readback(0x100, static_cast<std::uint32_t>(pattern.size()), {}, 5000ms);
  if (!mem) return failed(mem.error().message);
  auto color = c->read_register(protocol::index_of(Reg::CLEAR_COLOR), 2000ms);
  if (!color) return failed(color.error().message);
  g.memory = std::move(*mem);
  g.color = *color;
  g.ok = true;
  return g;
}

// The ERROR code a closed connection's last message carried (0 if none).
int last_error_code(const std::vector<std::uint8_t>& bytes) {
  protocol::MessageParser p;
  p.feed(bytes);
  int code = 0;
  protocol::Message m;
  while (p.next(m) == protocol::MessageParser::Status::Ok)
    if (auto* e = std::get_if<protocol::ErrorMsg>(&m.payload)) code = static_cast<int>(e->code);
  return code;
}

class DaemonHostile : public DaemonDirTest {};

TEST_F(DaemonHostile, BadClientsAreClosedAndTheGoodOneIsUnaffected) {
  ASSERT_TRUE(daemon_.start({"--listen", "unix:" + socket_, "--backend", "fake", "--log-level", "error",
                             "--handshake-timeout-ms", "1500", "--trickle-window-ms", "400", "--min-bytes-per-sec",
                             "200"}))
      << daemon_.error();
  std::vector<std::uint8_t> pattern(64 * 1024);
  std::mt19937 rng(42);
  for (auto& b : pattern) b = static_cast<std::uint8_t>(rng());

  // Reference run with nobody else connected.
  const auto reference = run_good_client(socket_, pattern);
  ASSERT_TRUE(reference.ok) << reference.error;
  ASSERT_EQ(reference.memory, pattern);

  // Garbage: random bytes.
  RawSocket garbage(socket_);
  std::vector<std::uint8_t> junk(512);
  for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
  junk[0] = 'X';  // never the magic
  ASSERT_TRUE(garbage.send(junk));
  // Truncated: a valid HELLO, then half of a WRITE_FRAMES message, then silence.
  RawSocket truncated(socket_);
  auto t = hello_bytes("truncated");
  const auto wf = protocol::encode(protocol::Message{2, protocol::WriteFrames{}});
  std::vector<std::uint8_t> half_header(wf.begin(), wf.begin() + 6);
  ASSERT_TRUE(truncated.send(t));
  ASSERT_TRUE(truncated.send(half_header));
  // Oversized: a header claiming a 4 GiB payload after the handshake.
  RawSocket oversized(socket_);
  auto o = hello_bytes("oversized");
  std::uint8_t big[protocol::kHeaderBytes];
  protocol::encode_header(protocol::MsgType::WriteFrames, 0xFFFFFFFFu, 3, big);
  o.insert(o.end(), big, big + sizeof big);
  ASSERT_TRUE(oversized.send(o));
  // Slowloris before the handshake: one byte every 100 ms of a HELLO.
  RawSocket slow_pre(socket_);
  // Slowloris after the handshake: a message trickling in at 10 bytes/s.
  RawSocket slow_post(socket_);
  ASSERT_TRUE(slow_post.send(hello_bytes("slowpost")));
  const auto t0 = std::chrono::steady_clock::now();
  auto trickle = std::async(std::launch::async, [&] {
    const auto h = hello_bytes("slowpre");
    const auto msg = protocol::encode(protocol::Message{9, protocol::Ping{std::vector<std::uint8_t>(60, 1)}});
    for (std::size_t i = 0; i < 100; ++i) {
      if (i < h.size() && !slow_pre.send(std::vector<std::uint8_t>{h[i]})) break;
      if (i < msg.size()) (void)slow_post.send(std::vector<std::uint8_t>{msg[i]});
      std::this_thread::sleep_for(100ms);
    }
  });

  const auto during = run_good_client(socket_, pattern);
  ASSERT_TRUE(during.ok) << during.error;
  EXPECT_EQ(during.memory, reference.memory);
  EXPECT_EQ(during.color, reference.color);

  auto [g_bytes, g_closed] = garbage.read_until_closed(3s);
  EXPECT_TRUE(g_closed);
  EXPECT_EQ(last_error_code(g_bytes), static_cast<int>(protocol::ErrorCode::BadMagic));
  auto [o_bytes, o_closed] = oversized.read_until_closed(3s);
  EXPECT_TRUE(o_closed);
  EXPECT_EQ(last_error_code(o_bytes), static_cast<int>(protocol::ErrorCode::TooLarge));
  auto [t_bytes, t_closed] = truncated.read_until_closed(5s);
  EXPECT_TRUE(t_closed);
  EXPECT_EQ(last_error_code(t_bytes), static_cast<int>(protocol::ErrorCode::Timeout));
  auto [sp_bytes, sp_closed] = slow_pre.read_until_closed(10s);
  EXPECT_TRUE(sp_closed);
  EXPECT_EQ(last_error_code(sp_bytes), static_cast<int>(protocol::ErrorCode::Timeout));
  auto [so_bytes, so_closed] = slow_post.read_until_closed(10s);
  EXPECT_TRUE(so_closed);
  EXPECT_EQ(last_error_code(so_bytes), static_cast<int>(protocol::ErrorCode::Timeout));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 10s);
  trickle.get();

  // And afterwards the daemon still serves a good client identically.
  const auto after = run_good_client(socket_, pattern);
  ASSERT_TRUE(after.ok) << after.error;
  EXPECT_EQ(after.memory, reference.memory);
}

TEST_F(DaemonHostile, SubscriberThatNeverReadsKeepsDaemonMemoryBounded) {
  // 640x480 RGBA frames: 600 of them queued would be ~700 MiB.
  ASSERT_TRUE(daemon_.start({"--listen", "unix:" + socket_, "--backend", "fake:640x480", "--log-level", "error"}))
      << daemon_.error();
  RawSocket lazy(socket_);
  auto sub = hello_bytes("lazy");
  const auto s = protocol::encode(protocol::Message{2, protocol::Subscribe{protocol::FrameFormat::Native, 0}});
  sub.insert(sub.end(), s.begin(), s.end());
  ASSERT_TRUE(lazy.send(sub));  // ... and never reads a byte

  auto drawer = client::Client::connect("unix:" + socket_, 2000ms);
  ASSERT_TRUE(drawer);
  ASSERT_TRUE(drawer->handshake("drawer", "", 2000ms));
  ASSERT_TRUE(drawer->acquire_lease(protocol::LeaseMode::Wait, 2000ms));
  const long rss_before = daemon_.rss_kib();
  ASSERT_GT(rss_before, 0);
  std::vector<std::uint8_t> frame;
  long rss_peak = rss_before;
  for (int i = 0; i < 600; ++i) {
    frame.clear();
    protocol::append(frame, protocol::write_frame(Reg::CLEAR_COLOR, static_cast<std::uint64_t>(i) << 8));
    protocol::append(frame, protocol::write_frame(Reg::FB_DISPLAY, 0));
    ASSERT_TRUE(drawer->write_frames(protocol::FrameView{frame}, 5000ms));
    if (i % 50 == 49) {
      ASSERT_TRUE(drawer->fence(5000ms));
      rss_peak = std::max(rss_peak, daemon_.rss_kib());
    }
  }
  ASSERT_TRUE(drawer->fence(5000ms));
  auto status = drawer->status(2000ms);
  ASSERT_TRUE(status);
  EXPECT_EQ(nlohmann::json::parse(*status)["frames"]["count"], 600);
  rss_peak = std::max(rss_peak, daemon_.rss_kib());
  // One pending frame + one in the socket + fixed slack; far below 600 queued frames.
  EXPECT_LT(rss_peak - rss_before, 48 * 1024) << "before " << rss_before << " KiB, peak " << rss_peak << " KiB";
}

}  // namespace
}  // namespace gpubridge::test
