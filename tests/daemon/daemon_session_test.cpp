// In-process tests: configuration parsing and the session dispatch over an in-memory stream.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <utility>

#include <nlohmann/json.hpp>

#include "gpubridge/daemon/config.hpp"
#include "gpubridge/daemon/hub.hpp"
#include "gpubridge/daemon/memory_stream.hpp"
#include "gpubridge/daemon/session.hpp"
#include "gpubridge/daemon/test_backends.hpp"

namespace gpubridge::daemon {
namespace {

using protocol::Message;
using protocol::Reg;

TEST(DaemonConfig, ParsesEveryKey) {
  const auto doc = nlohmann::json::parse(R"({
    "listen": ["unix:/tmp/x.sock", "tcp:127.0.0.1:7420"], "token": "t", "backend": "fake",
    "fallback_to_sim": false, "frames_dir": "f", "record_dir": "r", "log_level": "debug",
    "limits": {"max_message_bytes": 65536, "max_clients": 8, "handshake_timeout_ms": 500,
               "idle_timeout_ms": 0, "trickle_window_ms": 100, "min_bytes_per_sec": 10, "queue_bytes": 2097152}})");
  auto cfg = parse_config(doc, "t.json");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->listen.size(), 2u);
  EXPECT_EQ(cfg->backend, "fake");
  EXPECT_FALSE(cfg->fallback_to_sim);
  EXPECT_EQ(cfg->limits.max_clients, 8u);
  EXPECT_EQ(cfg->limits.max_message_bytes, 65536u);
  EXPECT_EQ(cfg->limits.queue_bytes, 2097152u);
  EXPECT_EQ(cfg->limits.idle_timeout_ms, 0u);
}

// The example shipped in configs/ is what people copy: it must load as it is.
TEST(DaemonConfig, ShippedExampleLoads) {
  auto cfg = load_config(std::filesystem::path(GPUBRIDGE_CONFIGS_DIR) / "gpubridged.json");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->backend, "sim");
  EXPECT_TRUE(cfg->fallback_to_sim);
  EXPECT_FALSE(cfg->mirror);
  EXPECT_EQ(cfg->reattach_interval_ms, 1000u);
}

TEST(DaemonConfig, ErrorsNameTheKeyAndTheProblem) {
  struct Case {
    const char* json;
    const char* message;
  } cases[] = {
      {R"({"limits": {"max_clients": "ten"}})", "c.json: limits.max_clients: expected an integer 1..4096, got \"ten\""},
      {R"({"limits": {"max_clients": 0}})", "c.json: limits.max_clients: expected an integer 1..4096, got 0"},
      {R"({"limits": {"max_clients": -3}})", "c.json: limits.max_clients: expected an integer 1..4096, got -3"},
      {R"({"limits": {"max_clients": 1.5}})", "c.json: limits.max_clients: expected an integer 1..4096, got 1.5"},
      {R"({"listen": ["ftp:x"]})", "c.json: listen[0]: bad address \"ftp:x\": unknown scheme"},
      {R"({"lisen": []})", "c.json: lisen: unknown key"},
      {R"({"limits": {"max_message_bytes": 99999999999}})", "c.json: limits.max_message_bytes: expected an integer 4096..16777216"},
      {R"({"token": 5})", "c.json: token: expected a string, got 5"},
      {R"([1])", "c.json: (top level): expected a JSON object"},
      // spdlog reads an unknown level as "off": the daemon would have run silently.
      {R"({"log_level": "verbose"})", "c.json: log_level: expected one of trace|debug|info|warn|error|off, got \"verbose\""},
  };
  for (const auto& c : cases) {
    auto cfg = parse_config(nlohmann::json::parse(c.json), "c.json");
    ASSERT_FALSE(cfg) << c.json;
    EXPECT_NE(cfg.error().message.find(c.message), std::string::npos) << cfg.error().message;
  }
}

// A number literal beyond double's range makes nlohmann::json throw out_of_range, not parse_error;
// load_config caught only parse_error, so such a file terminated gpubridged (fuzz_board_profile
// found it in the board profile reader, which read JSON the same way).
TEST(DaemonConfig, NumberBeyondDoubleRangeIsAnError) {
  const auto path = std::filesystem::temp_directory_path() / ("gpubridged-huge-" + std::to_string(::getpid()) + ".json");
  std::ofstream(path) << R"({"reattach_interval_ms": 1e999})";
  auto cfg = load_config(path);
  std::filesystem::remove(path);
  ASSERT_FALSE(cfg);
  EXPECT_NE(cfg.error().message.find("not valid JSON"), std::string::npos) << cfg.error().message;
}

// A wrong-typed value is described by its type, not dumped: dump() recursed once per nesting level
// and a deeply nested array overflowed the stack while the error was being written.
TEST(DaemonConfig, DeeplyNestedWrongValueIsAnError) {
  constexpr std::size_t kDepth = 200000;
  const std::string text = "{\"token\": " + std::string(kDepth, '[') + std::string(kDepth, ']') + "}";
  auto cfg = parse_config(nlohmann::json::parse(text), "c.json");
  ASSERT_FALSE(cfg);
  EXPECT_EQ(cfg.error().message, "c.json: token: expected a string, got an array");
}

// A long wrong-typed value is shortened for the message at a character boundary: cutting inside a
// multi-byte UTF-8 character left an invalid byte sequence in the error text.
TEST(DaemonConfig, ShortenedValueInAnErrorStaysUtf8) {
  std::string value = "a";  // then é, two bytes each: the dump is "aé..., so byte 37 falls inside an é
  for (int i = 0; i < 30; ++i) value += "\u00e9";
  auto cfg = parse_config(nlohmann::json::parse("{\"reattach_interval_ms\": \"" + value + "\"}"), "c.json");
  ASSERT_FALSE(cfg);
  const std::string& m = cfg.error().message;
  ASSERT_NE(m.find("..."), std::string::npos) << m;
  // Valid UTF-8: every lead byte is followed by exactly its continuation bytes.
  for (std::size_t i = 0; i < m.size();) {
    const auto b = static_cast<unsigned char>(m[i]);
    const std::size_t len = b < 0x80 ? 1 : (b >> 5) == 6 ? 2 : (b >> 4) == 14 ? 3 : (b >> 3) == 30 ? 4 : 0;
    ASSERT_NE(len, 0u) << "stray byte at " << i << " in: " << m;
    for (std::size_t k = 1; k < len; ++k)
      ASSERT_TRUE(i + k < m.size() && (static_cast<unsigned char>(m[i + k]) & 0xC0) == 0x80) << "cut character at " << i;
    i += len;
  }
}

// Flags set limits after the file was read: finalize_config checks them against the same ranges
// (they used to be clamped silently, to bounds other than the file's).
TEST(DaemonConfig, LimitsSetByFlagsAreCheckedLikeTheFile) {
  DaemonConfig cfg;
  cfg.limits.queue_bytes = 100;
  auto r = finalize_config(cfg);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message, "limits.queue_bytes (--queue-bytes): expected an integer 1048576..4294967296, got 100");
  cfg = {};
  cfg.limits.handshake_timeout_ms = 5;
  r = finalize_config(cfg);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("limits.handshake_timeout_ms (--handshake-timeout-ms): expected an integer 10..600000"),
            std::string::npos) << r.error().message;
  cfg = {};
  cfg.log_level = "loud";
  EXPECT_FALSE(finalize_config(cfg));
  EXPECT_TRUE(finalize_config(cfg = {}));
}

// --check-config prints the effective configuration in the file's own schema: it loads back to
// the same settings, and the token itself never appears.
TEST(DaemonConfig, EffectiveConfigurationLoadsBackAndHidesTheToken) {
  const auto dir = std::filesystem::temp_directory_path() / ("gpubridged-eff-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "token") << "s3cret-token\n";
  auto cfg = parse_config(nlohmann::json::parse(R"({
    "listen": ["unix:/tmp/x.sock", "tcp:0.0.0.0:7420"], "backend": "emulated:icebreaker", "mirror": true,
    "fallback_to_sim": false, "reattach_interval_ms": 250, "frames_dir": "f", "record_dir": "r", "log_level": "debug",
    "limits": {"max_message_bytes": 65536, "max_clients": 8, "handshake_timeout_ms": 500,
               "idle_timeout_ms": 0, "trickle_window_ms": 100, "min_bytes_per_sec": 10, "queue_bytes": 2097152}})"),
                          "t.json");
  ASSERT_TRUE(cfg) << cfg.error().message;
  cfg->token_file = (dir / "token").string();
  ASSERT_TRUE(finalize_config(*cfg));
  ASSERT_EQ(cfg->token, "s3cret-token");
  const auto doc = config_to_json(*cfg);
  EXPECT_EQ(doc.dump().find("s3cret"), std::string::npos) << doc.dump();
  auto again = parse_config(doc, "effective");
  ASSERT_TRUE(again) << again.error().message;
  ASSERT_TRUE(finalize_config(*again));
  EXPECT_EQ(again->token, "s3cret-token");  // read again from token_file
  EXPECT_EQ(config_to_json(*again), doc);
  EXPECT_EQ(again->limits.queue_bytes, 2097152u);
  EXPECT_EQ(again->reattach_interval_ms, 250u);
  EXPECT_TRUE(again->mirror);
  // A token given directly is left out, not written in clear.
  DaemonConfig direct;
  direct.token = "s3cret-token";
  EXPECT_EQ(config_to_json(direct).dump().find("s3cret"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// frames_dir / record_dir are checked before the daemon starts (and by --check-config): a path
// through a regular file, or (for users other than root, whom permissions do not stop) a directory
// the daemon may not write, is refused with the key named; a directory still to be created is fine.
TEST(DaemonConfig, OutputDirectoriesMustBeWritableOrCreatable) {
  const auto dir = std::filesystem::temp_directory_path() / ("gpubridged-out-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "file") << "x";
  DaemonConfig cfg;
  EXPECT_TRUE(check_output_dirs(cfg));  // unset
  cfg.frames_dir = (dir / "new" / "frames").string();
  cfg.record_dir = dir.string();
  EXPECT_TRUE(check_output_dirs(cfg)) << check_output_dirs(cfg).error().message;
  cfg.record_dir = (dir / "file" / "rec").string();
  auto r = check_output_dirs(cfg);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message, "record_dir: " + cfg.record_dir + ": " + (dir / "file").string() + " is not a directory");
  if (::geteuid() != 0) {
    std::filesystem::create_directories(dir / "ro");
    std::filesystem::permissions(dir / "ro", std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    cfg.record_dir = (dir / "ro" / "rec").string();
    r = check_output_dirs(cfg);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("is not writable by this user"), std::string::npos) << r.error().message;
    std::filesystem::permissions(dir / "ro", std::filesystem::perms::owner_all);
  }
  std::filesystem::remove_all(dir);
}

TEST(DaemonConfig, NonLoopbackTcpWithoutTokenIsRefused) {
  DaemonConfig cfg;
  cfg.listen = {"tcp:0.0.0.0:7420"};
  auto r = finalize_config(cfg);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("set a token"), std::string::npos);
  cfg.token = "x";
  EXPECT_TRUE(finalize_config(cfg));
  DaemonConfig local;
  local.listen = {"tcp:127.0.0.1:7420", "tcp:[::1]:1"};
  EXPECT_TRUE(finalize_config(local));
}

// Runs one client byte stream through a real Session over a MemoryStream, split into reads of
// `chunk` bytes, and returns the parsed replies.
std::vector<Message> run_session(const std::vector<std::uint8_t>& input, std::size_t chunk, std::vector<std::uint8_t>& raw) {
  boost::asio::io_context io;
  HubOptions opts;
  Hub hub(io.get_executor(), io.get_executor(), std::make_unique<FakeScanoutBackend>(), opts);
  raw.clear();
  auto stream = std::make_unique<MemoryStream>(io.get_executor(), input, std::vector<std::size_t>{chunk}, &raw);
  std::make_shared<Session>(hub, std::move(stream), io.get_executor())->start();
  io.run_for(std::chrono::seconds(5));
  protocol::MessageParser p;
  p.feed(raw);
  std::vector<Message> out;
  for (;;) {
    Message m;
    if (p.next(m) != protocol::MessageParser::Status::Ok) break;
    out.push_back(std::move(m));
  }
  return out;
}

TEST(DaemonSession, DispatchIsIndependentOfReadSplitPoints) {
  std::vector<std::uint8_t> in;
  auto add = [&](std::uint32_t id, protocol::Payload p) { protocol::encode(Message{id, std::move(p)}, in); };
  add(1, protocol::Hello{protocol::kSocketVersion, "split", ""});
  add(2, protocol::LeaseAcquire{protocol::LeaseMode::FailIfBusy});
  std::vector<std::uint8_t> frames;
  protocol::append(frames, protocol::write_frame(Reg::CLEAR_COLOR, 0xCAFEF00D));
  protocol::append(frames, protocol::write_frame(Reg::FB_DISPLAY, 0));
  add(3, protocol::WriteFrames{protocol::FrameView{frames}});
  add(4, protocol::ReadReg{protocol::index_of(Reg::CLEAR_COLOR)});
  add(5, protocol::FenceMsg{5});
  add(6, protocol::Bye{});

  std::vector<std::uint8_t> whole_raw;
  const auto whole = run_session(in, in.size(), whole_raw);
  ASSERT_EQ(whole.size(), 5u);  // WELCOME, LEASE_GRANTED, REG_VALUE, FENCE_DONE, BYE
  EXPECT_TRUE(std::holds_alternative<protocol::Welcome>(whole[0].payload));
  EXPECT_TRUE(std::holds_alternative<protocol::LeaseGranted>(whole[1].payload));
  ASSERT_TRUE(std::holds_alternative<protocol::RegValue>(whole[2].payload));
  EXPECT_EQ(std::get<protocol::RegValue>(whole[2].payload).value, 0xCAFEF00Du);
  EXPECT_EQ(whole[2].request_id, 4u);
  EXPECT_TRUE(std::holds_alternative<protocol::FenceDone>(whole[3].payload));
  EXPECT_TRUE(std::holds_alternative<protocol::Bye>(whole[4].payload));
  for (std::size_t chunk : {1, 2, 3, 5, 8, 13, 100}) {
    std::vector<std::uint8_t> raw;
    run_session(in, chunk, raw);
    EXPECT_EQ(raw, whole_raw) << "chunk " << chunk;
  }
}

TEST(DaemonSession, MessagesBeforeHelloAreRefused) {
  std::vector<std::uint8_t> in;
  protocol::encode(Message{7, protocol::StatusReq{}}, in);
  std::vector<std::uint8_t> raw;
  const auto out = run_session(in, in.size(), raw);
  ASSERT_EQ(out.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<protocol::ErrorMsg>(out[0].payload));
  EXPECT_EQ(std::get<protocol::ErrorMsg>(out[0].payload).code, protocol::ErrorCode::NotHandshaken);
  EXPECT_EQ(std::get<protocol::ErrorMsg>(out[0].payload).ref, 7u);
}

// Which messages a client may send comes from the message structs (protocol::sender): one of each
// server-to-client type after a good HELLO is answered with ERROR UNKNOWN_TYPE naming it, and the
// connection ends; PING, which either side sends, is answered.
TEST(DaemonSession, ServerToClientMessagesFromAClientAreRefused) {
  static const std::uint8_t pixel[4] = {1, 2, 3, 4};
  protocol::FrameData frame;
  frame.width = frame.height = 1;
  frame.format = protocol::PixelFormat::RGBA8888;
  frame.pixels = pixel;
  const protocol::Payload server_only[] = {
      protocol::Welcome{protocol::kSocketVersion, 1u << 20, 1, "{}"},
      protocol::ErrorMsg{},
      protocol::RegValue{},
      protocol::UploadAck{},
      protocol::ReadbackData{0, true, pixel},
      protocol::FenceDone{},
      protocol::StatusReply{"{}"},
      frame,
      protocol::LeaseGranted{},
      protocol::LeaseReleased{},
      protocol::DeviceEvent{R"({"event":"x"})"}};
  // Every server-to-client type of the Payload list is above, once: a new one must be added here.
  constexpr std::size_t server_types = []<std::size_t... I>(std::index_sequence<I...>) {
    return ((std::variant_alternative_t<I, protocol::Payload>::kSender == protocol::Sender::Server ? 1u : 0u) + ...);
  }(std::make_index_sequence<std::variant_size_v<protocol::Payload>>{});
  std::set<protocol::MsgType> listed;
  for (const auto& payload : server_only) listed.insert(protocol::type_of(payload));
  EXPECT_EQ(listed.size(), std::size(server_only));
  EXPECT_EQ(listed.size(), server_types);
  for (const auto& payload : server_only) {
    const auto type = protocol::type_of(payload);
    SCOPED_TRACE(std::string(protocol::to_string(type)));
    ASSERT_EQ(protocol::sender(type), protocol::Sender::Server);
    std::vector<std::uint8_t> in;
    protocol::encode(Message{1, protocol::Hello{protocol::kSocketVersion, "s", ""}}, in);
    protocol::encode(Message{2, payload}, in);
    protocol::encode(Message{3, protocol::Ping{{1, 2}}}, in);
    std::vector<std::uint8_t> raw;
    const auto out = run_session(in, in.size(), raw);
    ASSERT_EQ(out.size(), 2u);  // WELCOME, ERROR; the PING after it is never read
    ASSERT_TRUE(std::holds_alternative<protocol::ErrorMsg>(out[1].payload));
    const auto& e = std::get<protocol::ErrorMsg>(out[1].payload);
    EXPECT_EQ(e.code, protocol::ErrorCode::UnknownType);
    EXPECT_EQ(e.ref, 2u);
    EXPECT_EQ(e.text, std::string(protocol::to_string(type)) + " is a server-to-client message");
  }
  std::vector<std::uint8_t> in;
  protocol::encode(Message{1, protocol::Hello{protocol::kSocketVersion, "s", ""}}, in);
  protocol::encode(Message{2, protocol::Ping{{1, 2}}}, in);
  std::vector<std::uint8_t> raw;
  const auto out = run_session(in, in.size(), raw);
  ASSERT_EQ(out.size(), 2u);
  ASSERT_TRUE(std::holds_alternative<protocol::Pong>(out[1].payload));
  EXPECT_EQ(std::get<protocol::Pong>(out[1].payload).data, (std::vector<std::uint8_t>{1, 2}));
}

TEST(DaemonSession, ReadFramesInAWriteBatchAreRejected) {
  std::vector<std::uint8_t> in;
  protocol::encode(Message{1, protocol::Hello{protocol::kSocketVersion, "r", ""}}, in);
  protocol::encode(Message{2, protocol::LeaseAcquire{protocol::LeaseMode::Wait}}, in);
  std::vector<std::uint8_t> frames;
  protocol::append(frames, protocol::read_frame(Reg::STATUS));
  protocol::encode(Message{3, protocol::WriteFrames{protocol::FrameView{frames}}}, in);
  std::vector<std::uint8_t> raw;
  const auto out = run_session(in, in.size(), raw);
  // The parser already refuses read frames inside WRITE_FRAMES: ERROR BAD_FRAME, then the
  // connection ends (nothing of the batch reaches the device).
  ASSERT_EQ(out.size(), 3u);
  ASSERT_TRUE(std::holds_alternative<protocol::ErrorMsg>(out[2].payload));
  EXPECT_EQ(std::get<protocol::ErrorMsg>(out[2].payload).code, protocol::ErrorCode::BadFrame);
}

}  // namespace
}  // namespace gpubridge::daemon
