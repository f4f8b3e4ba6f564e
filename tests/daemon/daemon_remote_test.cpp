// Remote use (issue 21): pipelined fences through a link with latency, TLS with pinned
// fingerprints, WRITE_FRAMES compression (byte-identical device commands, bounded inflation),
// address and token from the environment. A real gpubridged on loopback TCP, reached directly or
// through DelayProxy (bench/include/gpubridge/bench/delay_proxy.hpp), which adds latency.
#include <gtest/gtest.h>
#include <zstd.h>

#include <nlohmann/json.hpp>

#include "daemon_fixture.hpp"
#include "daemon_process.hpp"
#include "gpubridge/bench/delay_proxy.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/common/trace_files.hpp"
#include "gpubridge/protocol/text_trace.hpp"

namespace gpubridge::test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

class DaemonRemote : public DaemonDirTest {
 protected:
  void SetUp() override {
    DaemonDirTest::SetUp();
    known_hosts_ = (dir_ / "known_hosts").string();
  }
  // A daemon on loopback TCP (port chosen by the kernel) with its TLS key in the test directory.
  void start(std::vector<std::string> extra = {}, const std::string& listen = "tcp:127.0.0.1:0") {
    std::vector<std::string> args{"--listen", listen, "--backend", "fake", "--log-level", "warn",
                                  "--tls-dir", (dir_ / "tls").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    ASSERT_TRUE(daemon_.start(args)) << daemon_.error();
    const std::string ep = daemon_.endpoints().at(0);
    port_ = static_cast<std::uint16_t>(std::stoi(ep.substr(ep.rfind(':') + 1)));
  }
  std::string fingerprint() const {
    auto r = run_process({GPUBRIDGED_PATH, "--tls-fingerprint", "--tls-dir", (dir_ / "tls").string()}, 10s);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.out.substr(0, r.out.find('\n'));
  }
  // The CLI with a private known-hosts file and nothing from the caller's environment.
  ProcessResult cli(std::vector<std::string> args, std::vector<std::string> env = {}) {
    args.insert(args.begin(), GPUBRIDGE_CLI_PATH);
    env.insert(env.begin(), {"GPUBRIDGE_KNOWN_HOSTS=" + known_hosts_, "GPUBRIDGE_ADDRESS=", "GPUBRIDGE_TOKEN=",
                             "GPUBRIDGE_TOKEN_FILE=", "GPUBRIDGE_TLS_FINGERPRINT=", "GPUBRIDGE_COMPRESS="});
    return run_process(args, 60s, env);
  }
  // A trace of `frames` swaps, each followed by a fence (what `play` paces on); each frame draws a
  // strip of 60 vertices, so its WRITE_FRAMES message is large enough to compress.
  std::string fenced_trace(int frames) {
    const auto path = dir_ / "fenced.trace";
    std::ofstream out(path);
    out << "FB_FORMAT FORMAT=RGB565 WIDTH=64 HEIGHT=64\nTRI_MODE GOURAUD=1\n";
    for (int i = 0; i < frames; ++i) {
      out << "CLEAR_COLOR R=" << (i * 5) % 256 << " G=16 B=48 A=255\nCLEAR\nPRIM TYPE=STRIP\n";
      for (int v = 0; v < 60; ++v)
        out << "COLOR R=" << (v * 4) % 256 << " A=255\nVERTEX X=" << (v % 2 ? 60 : 4) << " Y=" << v << "\n";
      out << "FB_DISPLAY 0\n.fence " << i + 1 << "\n";
    }
    return path.string();
  }

  std::string known_hosts_;
  std::uint16_t port_ = 0;
};

double play_seconds(const ProcessResult& r) {
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out, nullptr, false);
  return j.is_object() ? j.value("seconds", -1.0) : -1.0;
}

// Fails without pipelined fences: each .fence then costs a round trip (>= 40 x 50 ms), and a
// window that is not kept (no waiting at all) would finish in about one round trip.
TEST_F(DaemonRemote, PlayKeepsItsWindowOverA50msRoundTrip) {
  start();
  bench::DelayProxy proxy(port_, 25ms);  // 50 ms round trip
  const std::string trace = fenced_trace(40);
  const std::string at = "tcp:127.0.0.1:" + std::to_string(proxy.port());
  const double pipelined = play_seconds(cli({"play", trace, "--connect", at, "--window", "8", "--json"}));
  const double strict = play_seconds(cli({"play", trace, "--connect", at, "--sync", "--json"}));
  EXPECT_GE(strict, 40 * 0.050) << "sync: one round trip per fence";
  // 40 fences, at most 8 in flight: at least 40/8 - 1 full round trips of waiting, and far fewer
  // than one per fence.
  EXPECT_GE(pipelined, 4 * 0.050) << "the window of 8 was not kept";
  EXPECT_LT(pipelined, strict / 2) << "pipelined " << pipelined << " s vs sync " << strict << " s";
}

TEST_F(DaemonRemote, TlsFingerprintIsPinnedAndAMismatchRefused) {
  start({}, "tls:127.0.0.1:0");
  const std::string fp = fingerprint();
  ASSERT_EQ(fp.rfind("SHA256:", 0), 0u) << fp;
  const std::string at = "tls:127.0.0.1:" + std::to_string(port_);
  // Given the right fingerprint: accepted, and STATUS says the connection is encrypted.
  auto ok = cli({"status", "--connect", at, "--json"}, {"GPUBRIDGE_TLS_FINGERPRINT=" + fp});
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  const auto status = nlohmann::json::parse(ok.out);
  EXPECT_EQ(status["tls"]["fingerprint"], fp);
  bool saw_tls = false;
  for (const auto& c : status["clients"]) saw_tls = saw_tls || c["encryption"] == "tls";
  EXPECT_TRUE(saw_tls) << ok.out;
  // Given a wrong one: refused before the token or anything else is sent.
  auto wrong = cli({"status", "--connect", at}, {"GPUBRIDGE_TLS_FINGERPRINT=SHA256:" + std::string(64, '0')});
  EXPECT_EQ(wrong.exit_code, 1);
  EXPECT_NE(wrong.err.find("presented certificate " + fp), std::string::npos) << wrong.err;
  // Trust on first use: recorded in known_hosts, then a changed pin is refused.
  auto first = cli({"status", "--connect", at});
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_NE(first.err.find("trusting the daemon"), std::string::npos) << first.err;
  std::ifstream in(known_hosts_);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "127.0.0.1:" + std::to_string(port_) + " " + fp);
  EXPECT_EQ(cli({"status", "--connect", at}).exit_code, 0);
  std::ofstream(known_hosts_) << "127.0.0.1:" << port_ << " SHA256:" << std::string(64, 'a') << "\n";
  auto changed = cli({"status", "--connect", at});
  EXPECT_EQ(changed.exit_code, 1);
  EXPECT_NE(changed.err.find("known_hosts:1 pins"), std::string::npos) << changed.err;
}

TEST_F(DaemonRemote, ATlsOnlyListenerRefusesPlainClientsAndSaysWhy) {
  start({}, "tls:127.0.0.1:0");
  auto plain = cli({"status", "--connect", "tcp:127.0.0.1:" + std::to_string(port_)});
  EXPECT_EQ(plain.exit_code, 1);
  EXPECT_NE(plain.err.find("takes TLS only"), std::string::npos) << plain.err;
}

TEST_F(DaemonRemote, LoopbackPlainTcpSaysSoInStatus) {
  start();
  auto r = cli({"status", "--connect", "tcp:127.0.0.1:" + std::to_string(port_), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto status = nlohmann::json::parse(r.out);
  ASSERT_EQ(status["clients"].size(), 1u);
  EXPECT_EQ(status["clients"][0]["encryption"], "none (plain TCP)");
}

// Compression must not change what reaches the device: the commands in the daemon's recordings of
// the same play with and without zstd are identical (as text traces: the recordings' timestamps and
// session names differ), and the compressed play took fewer bytes on the wire.
TEST_F(DaemonRemote, CompressionOnAndOffGiveIdenticalDeviceCommands) {
  const auto rec = dir_ / "rec";
  start({"--record", rec.string()});
  const std::string trace = fenced_trace(30);
  const std::string at = "tcp:127.0.0.1:" + std::to_string(port_);
  auto z = cli({"play", trace, "--connect", at, "--json"}, {"GPUBRIDGE_COMPRESS=zstd"});
  auto plain = cli({"play", trace, "--connect", at, "--json"}, {"GPUBRIDGE_COMPRESS=none"});
  ASSERT_EQ(z.exit_code, 0) << z.err;
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const auto jz = nlohmann::json::parse(z.out), jp = nlohmann::json::parse(plain.out);
  EXPECT_TRUE(jz["compressed"].get<bool>());
  EXPECT_FALSE(jp["compressed"].get<bool>());
  EXPECT_EQ(jz["frame_bytes"], jp["frame_bytes"]);
  EXPECT_LT(jz["frame_wire_bytes"].get<double>(), jp["frame_wire_bytes"].get<double>());
  daemon_.stop();  // recordings are complete once the sessions ended
  std::vector<std::string> recordings;
  for (const auto& e : fs::directory_iterator(rec)) recordings.push_back(e.path().string());
  ASSERT_EQ(recordings.size(), 2u);
  auto commands = [](const std::string& p) {
    auto s = load_trace(p);
    EXPECT_TRUE(s) << (s ? "" : s.error().message);
    if (!s) return std::string();
    s->metadata_json = "{}";
    for (auto& c : s->commands) c.timestamp_ns = 0;
    return protocol::write_text_trace(*s);
  };
  const std::string a = commands(recordings[0]), b = commands(recordings[1]);
  EXPECT_NE(a.find("FB_DISPLAY"), std::string::npos) << a;
  EXPECT_EQ(a, b) << "the recorded device commands differ between compressed and plain play";
}

// A raw client: HELLO (optionally offering zstd), lease, then whatever the test sends.
class RawTcp {
 public:
  explicit RawTcp(std::uint16_t port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    timeval tv{5, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~RawTcp() { ::close(fd_); }
  void send(const protocol::Message& m) { send_bytes(protocol::encode(m)); }
  void send_bytes(const std::vector<std::uint8_t>& b) { (void)!::send(fd_, b.data(), b.size(), MSG_NOSIGNAL); }
  // Next message (ignoring PINGs), or nullopt at end of stream / timeout.
  std::optional<protocol::Message> next() {
    for (;;) {
      protocol::Message m;
      if (parser_.next(m) == protocol::MessageParser::Status::Ok) {
        if (std::holds_alternative<protocol::Ping>(m.payload)) continue;
        return m;
      }
      std::uint8_t buf[4096];
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) return std::nullopt;
      parser_.feed({buf, static_cast<std::size_t>(n)});
    }
  }
  bool connected() const { return connected_; }

 private:
  int fd_ = -1;
  bool connected_ = false;
  protocol::MessageParser parser_;
};

std::vector<std::uint8_t> zstd_of(const std::vector<std::uint8_t>& raw) {
  std::vector<std::uint8_t> out(ZSTD_compressBound(raw.size()));
  out.resize(ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), 1));
  return out;
}

protocol::Message write_z(std::uint32_t id, std::uint32_t frames_bytes, const std::vector<std::uint8_t>& data) {
  return {id, protocol::WriteFramesZ{protocol::Codec::Zstd, frames_bytes, data}};
}

std::optional<protocol::ErrorMsg> error_of(const std::optional<protocol::Message>& m) {
  if (const auto* e = m ? std::get_if<protocol::ErrorMsg>(&m->payload) : nullptr) return *e;
  return std::nullopt;
}

// Inflation is bounded by the declared size before it starts: a "zip bomb" (1 MiB of zeros in a
// few dozen bytes, declared as one frame) is refused with a clear error, and another client is
// served meanwhile and afterwards.
TEST_F(DaemonRemote, CompressedBatchesAreBoundedBeforeInflating) {
  start({"--max-message", "65536"});
  RawTcp bystander(port_);
  protocol::Hello hb;
  hb.name = "bystander";
  bystander.send({1, hb});
  ASSERT_TRUE(bystander.next());  // WELCOME

  auto open = [&](bool offer) {
    auto c = std::make_unique<RawTcp>(port_);
    protocol::Hello h;
    h.name = "bomber";
    if (offer) h.codecs = protocol::codec_bit(protocol::Codec::Zstd);
    c->send({1, h});
    auto w = c->next();
    EXPECT_TRUE(w && std::holds_alternative<protocol::Welcome>(w->payload));
    if (w && offer) {
      EXPECT_NE(std::get<protocol::Welcome>(w->payload).json.find("\"compression\":\"zstd\""), std::string::npos);
    }
    c->send({2, protocol::LeaseAcquire{}});
    EXPECT_TRUE(c->next());  // LEASE_GRANTED
    return c;
  };
  const std::vector<std::uint8_t> zeros(1 << 20, 0);
  {  // A bomb: declares 9 bytes, inflates to 1 MiB.
    auto c = open(true);
    c->send(write_z(3, 9, zstd_of(zeros)));
    const auto e = error_of(c->next());
    ASSERT_TRUE(e);
    EXPECT_EQ(e->code, protocol::ErrorCode::Malformed);
    EXPECT_NE(e->text.find("does not inflate to the declared 9 frames_bytes"), std::string::npos) << e->text;
    EXPECT_FALSE(c->next()) << "the connection must be closed";
  }
  {  // Declares more than the daemon's maximum payload: refused before a byte is inflated.
    auto c = open(true);
    c->send(write_z(3, 9 * 100000, zstd_of(std::vector<std::uint8_t>(9 * 100000, 0))));
    const auto e = error_of(c->next());
    ASSERT_TRUE(e);
    EXPECT_EQ(e->code, protocol::ErrorCode::TooLarge);
    EXPECT_NE(e->text.find("exceeds the maximum payload of 65536"), std::string::npos) << e->text;
  }
  {  // Not negotiated at HELLO.
    auto c = open(false);
    c->send(write_z(3, 9, zstd_of(std::vector<std::uint8_t>(9, 0))));
    const auto e = error_of(c->next());
    ASSERT_TRUE(e);
    EXPECT_EQ(e->code, protocol::ErrorCode::Malformed);
    EXPECT_NE(e->text.find("HELLO offered no codec"), std::string::npos) << e->text;
  }
  {  // A read frame hidden inside the compressed data.
    auto c = open(true);
    std::vector<std::uint8_t> raw;
    protocol::append(raw, protocol::Frame{true, 0, 0});
    c->send(write_z(3, 9, zstd_of(raw)));
    const auto e = error_of(c->next());
    ASSERT_TRUE(e);
    EXPECT_EQ(e->code, protocol::ErrorCode::BadFrame);
  }
  bystander.send({2, protocol::Ping{{'o', 'k'}}});
  auto pong = bystander.next();
  ASSERT_TRUE(pong && std::holds_alternative<protocol::Pong>(pong->payload));
}

// One environment points every program at a remote daemon: address, token (or token file).
TEST_F(DaemonRemote, AddressAndTokenComeFromTheEnvironment) {
  start({"--token", "s3cret"});
  const std::string at = "tcp:127.0.0.1:" + std::to_string(port_);
  auto none = cli({"status"}, {"GPUBRIDGE_ADDRESS=" + at});
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_NE(none.err.find("AUTH_FAILED"), std::string::npos) << none.err;
  auto env = cli({"status"}, {"GPUBRIDGE_ADDRESS=" + at, "GPUBRIDGE_TOKEN=s3cret"});
  EXPECT_EQ(env.exit_code, 0) << env.err;
  std::ofstream(dir_ / "token") << "s3cret\n";
  auto file = cli({"status"}, {"GPUBRIDGE_ADDRESS=" + at, "GPUBRIDGE_TOKEN_FILE=" + (dir_ / "token").string()});
  EXPECT_EQ(file.exit_code, 0) << file.err;
  auto bad = cli({"status"}, {"GPUBRIDGE_ADDRESS=" + at, "GPUBRIDGE_TOKEN_FILE=" + (dir_ / "missing").string()});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("GPUBRIDGE_TOKEN_FILE="), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace gpubridge::test
