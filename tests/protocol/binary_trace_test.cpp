// Binary traces: layout, round trip, streaming reads, and every malformed-input class with the
// record index and byte offset in the message.
#include <gtest/gtest.h>

#include "gpubridge/protocol/text_trace.hpp"
#include "gpubridge/protocol/trace.hpp"
#include "trace_samples.hpp"

namespace gpubridge::protocol {
namespace {

using testing::expect_same_commands;
using testing::sample_stream;

std::vector<std::uint8_t> must_write(const CommandStream& s) {
  auto b = write_binary_trace(s);
  EXPECT_TRUE(b.ok()) << (b.ok() ? "" : b.error().message);
  return b.ok() ? *b : std::vector<std::uint8_t>{};
}

std::string read_error(std::span<const std::uint8_t> bytes) {
  auto r = read_binary_trace(bytes, "t.gbt");
  return r.ok() ? std::string("(no error)") : r.error().message;
}

TEST(BinaryTrace, HeaderLayout) {
  CommandStream s;
  s.metadata_json = "{ \"a\" :\n 1 }";  // multi-line metadata is stored compactly
  const auto b = must_write(s);
  const std::string compact = R"({"a":1})";
  ASSERT_EQ(b.size(), 16 + compact.size());
  EXPECT_EQ(std::string(b.begin(), b.begin() + 8), std::string("GBTRACE\0", 8));
  EXPECT_EQ(b[8], 1);
  EXPECT_EQ(b[9], 0);
  EXPECT_EQ(b[10], 0);
  EXPECT_EQ(b[11], 0);
  EXPECT_EQ(b[12], compact.size());
  EXPECT_EQ(std::string(b.begin() + 16, b.end()), compact);
}

TEST(BinaryTrace, OneLineMetadataIsKeptVerbatim) {
  CommandStream s;
  s.metadata_json = R"({ "a" : 1e3 })";
  const auto b = must_write(s);
  EXPECT_EQ(std::string(b.begin() + 16, b.end()), s.metadata_json);
}

TEST(BinaryTrace, RecordLayout) {
  CommandStream s;
  s.commands.push_back({0x0102, FenceCmd{5}});
  const auto b = must_write(s);
  const std::size_t r = 16 + 2;  // header + "{}"
  ASSERT_EQ(b.size(), r + 8 + 12 + 8);
  EXPECT_EQ(b[r], 0x02);
  EXPECT_EQ(b[r + 1], 0x01);
  EXPECT_EQ(b[r + 8], 'G');
  EXPECT_EQ(b[r + 11], 0x20);  // FENCE
  EXPECT_EQ(b[r + 16], 1);     // request id = record number 1
  EXPECT_EQ(b[r + 20], 5);
}

TEST(BinaryTrace, RoundTripKeepsEverything) {
  const auto s = sample_stream();
  const auto bytes = must_write(s);
  auto back = read_binary_trace(bytes, "t.gbt");
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->metadata_json, s.metadata_json);
  expect_same_commands(s, *back, true);
  EXPECT_EQ(must_write(*back), bytes);
}

// Hands out one byte per read: the reader must not assume full reads.
class TrickleSource final : public ByteSource {
 public:
  explicit TrickleSource(std::span<const std::uint8_t> b) : b_(b) {}
  Result<std::size_t> read(std::span<std::uint8_t> out) override {
    if (pos_ == b_.size() || out.empty()) return std::size_t{0};
    out[0] = b_[pos_++];
    return std::size_t{1};
  }

 private:
  std::span<const std::uint8_t> b_;
  std::size_t pos_ = 0;
};

TEST(BinaryTrace, StreamsFromAnySource) {
  const auto s = sample_stream();
  const auto bytes = must_write(s);
  TrickleSource src(bytes);
  BinaryTraceReader reader(src, "trickle");
  ASSERT_TRUE(reader.open().ok());
  std::size_t n = 0;
  TimedCommand c;
  for (;;) {
    auto more = reader.next(c);
    ASSERT_TRUE(more.ok()) << more.error().message;
    if (!*more) break;
    EXPECT_EQ(c.command, s.commands[n].command);
    ++n;
  }
  EXPECT_EQ(n, s.commands.size());
  EXPECT_EQ(reader.records_read(), n);
}

TEST(BinaryTrace, TruncatedAtEveryByte) {
  const auto bytes = must_write(sample_stream());
  // Record boundaries: a cut exactly there is a shorter, valid trace.
  std::vector<std::size_t> boundaries;
  {
    auto s = sample_stream();
    std::vector<std::uint8_t> acc;
    ASSERT_TRUE(append_trace_header(s.metadata_json, acc).ok());
    boundaries.push_back(acc.size());
    for (std::size_t i = 0; i < s.commands.size(); ++i) {
      ASSERT_TRUE(append_trace_record(s.commands[i], i + 1, acc).ok());
      boundaries.push_back(acc.size());
    }
  }
  for (std::size_t cut = 0; cut < bytes.size(); ++cut) {
    auto r = read_binary_trace(std::span(bytes).first(cut), "t.gbt");
    const auto it = std::find(boundaries.begin(), boundaries.end(), cut);
    if (it != boundaries.end()) {
      ASSERT_TRUE(r.ok()) << "cut " << cut << ": " << r.error().message;
      EXPECT_EQ(r->commands.size(), static_cast<std::size_t>(it - boundaries.begin()));
    } else {
      ASSERT_FALSE(r.ok()) << "cut " << cut;
      EXPECT_EQ(r.error().message.rfind("t.gbt: ", 0), 0u) << r.error().message;
      EXPECT_NE(r.error().message.find("byte"), std::string::npos) << r.error().message;
    }
  }
}

TEST(BinaryTrace, BadHeaders) {
  auto good = must_write(CommandStream{});
  auto b = good;
  b[0] = 'X';
  EXPECT_NE(read_error(b).find("not a gpubridge binary trace"), std::string::npos);
  b = good;
  b[8] = 2;
  EXPECT_NE(read_error(b).find("byte 8: trace version 2"), std::string::npos) << read_error(b);
  b = good;
  b[10] = 1;
  EXPECT_NE(read_error(b).find("flags 1 must be 0"), std::string::npos) << read_error(b);
  b = good;
  b[12] = 0x01, b[13] = 0x00, b[14] = 0x01;  // 65537
  EXPECT_NE(read_error(b).find("metadata length 65537"), std::string::npos) << read_error(b);
  b = good;
  b[16] = '[', b[17] = ']';
  EXPECT_NE(read_error(b).find("metadata is JSON but not an object"), std::string::npos) << read_error(b);
}

TEST(BinaryTrace, RecordErrorsNameRecordAndOffset) {
  CommandStream s;
  s.commands.push_back({5, FenceCmd{1}});
  auto base = must_write(s);  // header 18 bytes, record 0 is 28 bytes → record 1 starts at 46
  ASSERT_EQ(base.size(), 46u);

  // A PING record is not allowed in a trace.
  auto b = base;
  const std::uint8_t ts[8] = {9, 0, 0, 0, 0, 0, 0, 0};
  b.insert(b.end(), ts, ts + 8);
  const auto ping = encode(Message{2, Ping{{1}}});
  b.insert(b.end(), ping.begin(), ping.end());
  EXPECT_NE(read_error(b).find("record 1 at byte 54: PING cannot appear in a trace"), std::string::npos)
      << read_error(b);

  // Timestamps must not decrease.
  b = base;
  const std::uint8_t early[8] = {4, 0, 0, 0, 0, 0, 0, 0};
  b.insert(b.end(), early, early + 8);
  const auto fence = encode(Message{2, FenceMsg{2}});
  b.insert(b.end(), fence.begin(), fence.end());
  EXPECT_NE(read_error(b).find("record 1 at byte 46: timestamp 4 ns is earlier"), std::string::npos) << read_error(b);

  // A WRITE_FRAMES record with a read frame, and a record with an unknown message type.
  b = base;
  b.insert(b.end(), ts, ts + 8);
  std::vector<std::uint8_t> frames;
  append(frames, read_frame(Reg::STATUS));
  const auto wf = encode(Message{2, WriteFrames{FrameView{frames}}});
  b.insert(b.end(), wf.begin(), wf.end());
  EXPECT_NE(read_error(b).find("record 1 at byte 66: WRITE_FRAMES frame 0"), std::string::npos) << read_error(b);
  b = base;
  b.insert(b.end(), ts, ts + 8);
  auto bad = encode(Message{2, FenceMsg{2}});
  bad[3] = 0x7E;
  b.insert(b.end(), bad.begin(), bad.end());
  EXPECT_NE(read_error(b).find("unknown message type 0x7E"), std::string::npos) << read_error(b);
}

TEST(BinaryTrace, HugeClaimedPayloadInShortFileFailsCleanly) {
  auto b = must_write(CommandStream{});
  const std::uint8_t ts[8] = {};
  b.insert(b.end(), ts, ts + 8);
  std::uint8_t h[kHeaderBytes];
  encode_header(MsgType::Upload, kMaxPayload, 1, h);
  b.insert(b.end(), h, h + kHeaderBytes);
  b.insert(b.end(), 100, 0);
  EXPECT_NE(read_error(b).find("ends"), std::string::npos) << read_error(b);
  encode_header(MsgType::Upload, kMaxPayload + 1, 1, b.data() + 18 + 8);
  EXPECT_NE(read_error(b).find("exceeds the maximum"), std::string::npos) << read_error(b);
}

TEST(BinaryTrace, WriterRejectsInvalidCommands) {
  CommandStream s;
  s.commands.push_back({0, UploadCmd{0, {}}});
  EXPECT_FALSE(write_binary_trace(s).ok());
  s.commands = {{0, FramesCmd{{0x80, 0, 0, 0, 0, 0, 0, 0, 0}}}};
  EXPECT_FALSE(write_binary_trace(s).ok());
  s.commands = {{5, FenceCmd{1}}, {4, FenceCmd{2}}};
  EXPECT_FALSE(write_binary_trace(s).ok());
  s.commands = {{0, ReadbackCmd{0, 0}}};
  EXPECT_FALSE(write_binary_trace(s).ok());
  s.commands.clear();
  s.metadata_json = "not json";
  EXPECT_FALSE(write_binary_trace(s).ok());
}

TEST(BinaryTrace, BinaryTextBinaryIsByteIdentical) {
  auto s = sample_stream();
  for (auto& c : s.commands) c.timestamp_ns = 0;  // text traces carry no timestamps
  const auto bytes = must_write(s);
  auto back = read_binary_trace(bytes, "t.gbt");
  ASSERT_TRUE(back.ok());
  const std::string text = write_text_trace(*back);
  auto again = parse_text_trace(text, "t.trace", {});
  ASSERT_TRUE(again.ok()) << again.error().message << "\n" << text;
  EXPECT_EQ(must_write(*again), bytes) << text;
  EXPECT_EQ(write_text_trace(*again), text);
}

// A CommandStream is spigpu commands: writing it under metadata naming another (or no) kind would
// make a trace every reader refuses, so the writer refuses it and says what to change.
TEST(BinaryTrace, WriterRefusesMetadataOfAnotherKind) {
  CommandStream s;
  s.commands.push_back(TimedCommand{0, FenceCmd{1}});
  s.metadata_json = R"({"device_kind":"dmc1"})";
  auto dmc1 = write_binary_trace(s);
  ASSERT_FALSE(dmc1);
  EXPECT_EQ(dmc1.error().message,
            "trace metadata says device_kind \"dmc1\", but the commands are spigpu register writes; remove "
            "\"device_kind\" or set it to \"spigpu\"");
  s.metadata_json = R"({"device_kind":7})";
  auto seven = write_binary_trace(s);
  ASSERT_FALSE(seven);
  EXPECT_EQ(seven.error().message, "trace metadata device_kind 7 is not a device kind (spigpu, dmc1)");
  s.metadata_json = R"({"device_kind":"spigpu"})";
  auto ok = write_binary_trace(s);
  ASSERT_TRUE(ok) << ok.error().message;
  auto back = read_binary_trace(*ok, "s.gbt");
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->commands, s.commands);
}

// A DMC-1 session's trace (docs/protocol.md 18.1): metadata "device_kind": "dmc1", records
// DMC1_WORDS and FENCE. The DMC-1 reader returns its words in order; the spigpu reader refuses it by
// kind, and an unknown kind is refused at the metadata.
TEST(BinaryTrace, Dmc1TracesNameTheirKind) {
  std::vector<std::uint8_t> out;
  ASSERT_TRUE(append_trace_header(R"({"source":"test","device_kind":"dmc1"})", out));
  const std::vector<std::uint64_t> a{0x0000FFFF3FBC0000ull, 0xC0000001ull}, b{0x1234'5678'9ABC'DEF0ull};
  std::vector<std::uint8_t> pa, pb;
  append_dmc1_words(a, pa);
  append_dmc1_words(b, pb);
  append_trace_message(10, Message{1, Dmc1Words{pa}}, out);
  append_trace_message(20, Message{2, FenceMsg{7}}, out);
  append_trace_message(30, Message{3, Dmc1Words{pb}}, out);
  auto kind = binary_trace_device_kind(out, "d.gbtrace");
  ASSERT_TRUE(kind) << kind.error().message;
  EXPECT_EQ(*kind, DeviceKind::Dmc1);
  auto words = read_dmc1_trace(out, "d.gbtrace");
  ASSERT_TRUE(words) << words.error().message;
  EXPECT_EQ(*words, (std::vector<std::uint64_t>{a[0], a[1], b[0]}));
  auto spigpu = read_binary_trace(out, "d.gbtrace");
  ASSERT_FALSE(spigpu);
  EXPECT_NE(spigpu.error().message.find("d.gbtrace: a DMC-1 trace (metadata \"device_kind\": \"dmc1\"), not a spigpu one"),
            std::string::npos)
      << spigpu.error().message;
  // A spigpu message in a DMC-1 trace, and a spigpu trace read as a DMC-1 one.
  auto bad = out;
  std::vector<std::uint8_t> frames;
  append(frames, write_frame(Reg::FB_DISPLAY, 0));
  append_trace_message(40, Message{4, WriteFrames{FrameView{frames}}}, bad);
  auto mixed = read_dmc1_trace(bad, "m.gbtrace");
  ASSERT_FALSE(mixed);
  EXPECT_NE(mixed.error().message.find("WRITE_FRAMES cannot appear in a trace (a DMC-1 trace holds only DMC1_WORDS and FENCE)"),
            std::string::npos)
      << mixed.error().message;
  std::vector<std::uint8_t> plain;
  ASSERT_TRUE(append_trace_header("{}", plain));
  EXPECT_EQ(*binary_trace_device_kind(plain, "p.gbt"), DeviceKind::Spigpu);
  EXPECT_FALSE(read_dmc1_trace(plain, "p.gbt"));
  std::vector<std::uint8_t> vga;
  ASSERT_TRUE(append_trace_header(R"({"device_kind":"vga"})", vga));
  auto unknown = binary_trace_device_kind(vga, "v.gbt");
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().message.find("metadata device_kind \"vga\" is not a device kind (spigpu, dmc1)"), std::string::npos)
      << unknown.error().message;
}

}  // namespace
}  // namespace gpubridge::protocol
