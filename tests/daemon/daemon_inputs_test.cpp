// Issue 14, careless input: configuration and token files that are not regular files or are huge,
// a 20 MB token in a text trace, a small PNG that decodes to 1 GiB, and a daemon announcing a tiny
// max_payload. Each gets a clear error, promptly, with bounded memory.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/un.h>
#include <zlib.h>

#include <future>
#include <thread>

#include "daemon_process.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::test {
namespace {

using namespace std::chrono_literals;

class CarelessInput : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = make_temp_dir(::testing::UnitTest::GetInstance()->current_test_info()->name()); }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

// Item 8: --config and --token-file take regular files of bounded size; a directory, a FIFO, a
// device or a huge file is refused at once (exit 2) with a message naming the file and the problem.
TEST_F(CarelessInput, ConfigAndTokenFilesMustBeSmallRegularFiles) {
  const auto fifo = dir_ / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto huge = dir_ / "huge.json";
  {
    std::ofstream out(huge);
    out << "{\"comment\": \"" << std::string(3u << 20, 'x') << "\"}";
  }
  struct Case {
    std::vector<std::string> args;
    std::string expect;
  } cases[] = {
      {{"--config", dir_.string()}, dir_.string() + ": is a directory"},
      {{"--config", fifo.string()}, fifo.string() + ": is not a regular file"},
      {{"--config", "/dev/zero"}, "/dev/zero: is not a regular file"},
      {{"--config", huge.string()}, "bytes exceeds the limit"},
      {{"--token-file", "/dev/zero"}, "/dev/zero: is not a regular file"},
      {{"--token-file", fifo.string()}, fifo.string() + ": is not a regular file"},
      {{"--token-file", dir_.string()}, dir_.string() + ": is a directory"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> argv{GPUBRIDGED_PATH, "--check-config", "--backend", "fake"};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = run_process(argv, 5s);
    SCOPED_TRACE(c.args[0] + " " + c.args[1]);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_LT(std::chrono::steady_clock::now() - t0, 3s);
    EXPECT_LT(r.max_rss_kib, 256 * 1024);
  }
}

// Item 9: a huge token in a text trace is shown shortened (and a NUL as \0) in the error, not echoed
// whole.
TEST_F(CarelessInput, AHugeTraceTokenIsShortenedInTheError) {
  for (const bool with_nul : {false, true}) {
    const auto trace = dir_ / "big.trace";
    {
      std::ofstream out(trace, std::ios::binary | std::ios::trunc);
      std::string token(20u << 20, '7');
      if (with_nul) token[10] = '\0';  // printed as \0, not cutting the message there
      out << "CLEAR_COLOR " << token << "\n";
    }
    const auto r = run_process({GPUBRIDGE_CLI_PATH, "render", trace.string(), "--out", (dir_ / "o.png").string()}, 30s);
    SCOPED_TRACE(with_nul ? "with a NUL" : "digits only");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.err.find("big.trace:1:13:"), std::string::npos) << r.err.substr(0, 400);
    EXPECT_NE(r.err.find("is not a value for CLEAR_COLOR"), std::string::npos) << r.err.substr(0, 400);
    EXPECT_LT(r.err.size(), 1000u) << r.err.substr(0, 400);
    if (with_nul) {
      EXPECT_NE(r.err.find("7777777777\\0777"), std::string::npos) << r.err.substr(0, 400);
    }
  }
}

// A valid 1-bit greyscale PNG of width x height, all black (compresses about 1000:1).
std::vector<std::uint8_t> black_png(std::uint32_t width, std::uint32_t height) {
  std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  auto be32 = [&](std::uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) png.push_back(static_cast<std::uint8_t>(v >> s));
  };
  auto chunk = [&](const char* type, const std::vector<std::uint8_t>& data) {
    be32(static_cast<std::uint32_t>(data.size()));
    const std::size_t start = png.size();
    png.insert(png.end(), type, type + 4);
    png.insert(png.end(), data.begin(), data.end());
    be32(static_cast<std::uint32_t>(crc32(0, &png[start], static_cast<uInt>(4 + data.size()))));
  };
  std::vector<std::uint8_t> ihdr;
  for (std::uint32_t v : {width, height})
    for (int s = 24; s >= 0; s -= 8) ihdr.push_back(static_cast<std::uint8_t>(v >> s));
  ihdr.insert(ihdr.end(), {1, 0, 0, 0, 0});
  chunk("IHDR", ihdr);
  const std::vector<std::uint8_t> raw(std::size_t{height} * (1 + width / 8), 0);
  uLongf packed = compressBound(static_cast<uLong>(raw.size()));
  std::vector<std::uint8_t> idat(packed);
  EXPECT_EQ(compress2(idat.data(), &packed, raw.data(), static_cast<uLong>(raw.size()), 9), Z_OK);
  idat.resize(packed);
  chunk("IDAT", idat);
  chunk("IEND", {});
  return png;
}

// Item 9: an .upload PNG whose pixels exceed the 64 MiB asset limit is refused from its header,
// before 1 GiB of RGBA is decoded.
TEST_F(CarelessInput, AnOversizedPngAssetIsRefusedBeforeDecoding) {
  const auto png = black_png(16384, 16384);
  ASSERT_LT(png.size(), 2u << 20);
  std::ofstream(dir_ / "huge.png", std::ios::binary).write(reinterpret_cast<const char*>(png.data()),
                                                            static_cast<std::streamsize>(png.size()));
  std::ofstream(dir_ / "asset.trace") << ".upload 0 png huge.png\n";
  const auto r =
      run_process({GPUBRIDGE_CLI_PATH, "render", (dir_ / "asset.trace").string(), "--out", (dir_ / "o.png").string()}, 60s);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("16384x16384"), std::string::npos) << r.err;
  EXPECT_LT(r.max_rss_kib, 256 * 1024) << "the PNG was decoded before its size was checked";
}

// Item 9: a WELCOME announcing a max_payload below the protocol's minimum fails the handshake with
// a message saying so (the upload loop used to spin on it).
TEST_F(CarelessInput, AWelcomeWithATinyMaxPayloadIsRefused) {
  const auto path = (dir_ / "fake.sock").string();
  const int listener = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un sa{};
  sa.sun_family = AF_UNIX;
  std::strncpy(sa.sun_path, path.c_str(), sizeof sa.sun_path - 1);
  ASSERT_EQ(::bind(listener, reinterpret_cast<sockaddr*>(&sa), sizeof sa), 0);
  ASSERT_EQ(::listen(listener, 1), 0);
  std::thread server([listener] {
    const int fd = ::accept(listener, nullptr, nullptr);
    std::uint8_t buf[512];
    (void)::recv(fd, buf, sizeof buf, 0);  // HELLO
    const auto welcome = protocol::encode(protocol::Message{1, protocol::Welcome{protocol::kSocketVersion, 4, 1, "{}"}});
    (void)::send(fd, welcome.data(), welcome.size(), MSG_NOSIGNAL);
    // Acknowledge whatever comes (an upload of empty chunks would never end).
    for (;;) {
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n <= 0) break;
      if (n >= static_cast<ssize_t>(protocol::kHeaderBytes) && buf[3] == static_cast<std::uint8_t>(protocol::MsgType::Upload)) {
        std::uint32_t id = 0;
        std::memcpy(&id, buf + 8, 4);
        const auto ack = protocol::encode(protocol::Message{id, protocol::UploadAck{0, 0}});
        (void)::send(fd, ack.data(), ack.size(), MSG_NOSIGNAL);
      }
    }
    ::close(fd);
  });
  std::atomic<int> outcome{0};  // 1 refused at the handshake, 2 upload returned, 0 still running
  std::string message;
  std::thread client([&] {
    auto c = client::Client::connect("unix:" + path, 2000ms);
    if (!c) return;
    auto h = c->handshake("tiny", "", 2000ms);
    if (!h) {
      message = h.error().message;
      outcome = 1;
      return;
    }
    std::vector<std::uint8_t> data(64, 1);
    auto u = c->upload(0, data, {}, 2000ms);
    message = u ? "upload succeeded" : u.error().message;
    outcome = 2;
  });
  for (int i = 0; i < 300 && outcome == 0; ++i) std::this_thread::sleep_for(10ms);
  ::shutdown(listener, SHUT_RDWR);
  ::close(listener);
  if (outcome == 0) {
    client.detach();  // spinning: leave it, the test has failed
    server.detach();
    FAIL() << "the client is still uploading 3 s later";
  }
  client.join();
  server.join();
  EXPECT_EQ(outcome.load(), 1) << message;
  EXPECT_NE(message.find("max_payload 4"), std::string::npos) << message;
}

}  // namespace
}  // namespace gpubridge::test
