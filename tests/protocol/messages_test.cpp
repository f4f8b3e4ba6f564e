// Socket messages: layouts written out by hand, round trips of every type, incremental feeding.
#include <gtest/gtest.h>

#include <set>

#include "gpubridge/protocol/messages.hpp"
#include "message_samples.hpp"

namespace gpubridge::protocol {
namespace {

using testing::make_samples;

struct Parsed {
  Message message;
  std::vector<std::uint8_t> reencoded;  // taken at once: payload spans live only until the next feed()/next()
};

std::vector<Parsed> parse_all(std::span<const std::uint8_t> bytes, std::size_t chunk, MessageParser& p) {
  std::vector<Parsed> out;
  for (std::size_t i = 0; i < bytes.size(); i += chunk) {
    p.feed(bytes.subspan(i, std::min(chunk, bytes.size() - i)));
    Message m;
    MessageParser::Status st;
    while ((st = p.next(m)) == MessageParser::Status::Ok) out.push_back({m, encode(m)});
    EXPECT_NE(st, MessageParser::Status::Error) << p.error().message;
  }
  return out;
}

TEST(Messages, SamplesCoverEveryType) {
  auto s = make_samples();
  std::set<std::size_t> kinds;
  for (const auto& m : s.messages) kinds.insert(m.payload.index());
  EXPECT_EQ(kinds.size(), std::variant_size_v<Payload>);
}

TEST(Messages, EveryTypeRoundTripsWholeAndByteByByte) {
  auto s = make_samples();
  for (std::size_t chunk : {std::size_t{1}, std::size_t{5}, std::size_t{4096}}) {
    std::vector<std::uint8_t> stream;
    for (const auto& m : s.messages) encode(m, stream);
    MessageParser p;
    auto got = parse_all(stream, chunk, p);
    ASSERT_EQ(got.size(), s.messages.size()) << "chunk " << chunk;
    for (std::size_t i = 0; i < got.size(); ++i) {
      SCOPED_TRACE(std::string(to_string(type_of(s.messages[i].payload))));
      EXPECT_EQ(got[i].message.request_id, s.messages[i].request_id);
      EXPECT_EQ(got[i].message.payload.index(), s.messages[i].payload.index());
      // Re-encoding what was decoded must give the bytes that were sent (no field lost).
      EXPECT_EQ(got[i].reencoded, encode(s.messages[i]));
    }
    EXPECT_EQ(p.buffered(), 0u);
  }
}

TEST(Messages, HeaderLayoutIsLittleEndian) {
  const auto b = encode(Message{0x0A0B0C0D, FenceMsg{0x1122334455667788ull}});
  const std::vector<std::uint8_t> expect = {'G', 'B', 1, 0x20, 8, 0, 0, 0, 0x0D, 0x0C, 0x0B, 0x0A,
                                            0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11};
  EXPECT_EQ(b, expect);
}

TEST(Messages, HelloLayout) {
  const auto b = encode(Message{1, Hello{0x0102, "ab", "xyz"}});
  const std::vector<std::uint8_t> payload(b.begin() + kHeaderBytes, b.end());
  EXPECT_EQ(payload, (std::vector<std::uint8_t>{0x02, 0x01, 2, 'a', 'b', 3, 'x', 'y', 'z'}));
}

// The optional codecs byte (docs/protocol.md 17.6) and WRITE_FRAMES_Z, byte by byte.
TEST(Messages, HelloCodecsAndCompressedWriteLayout) {
  const auto h = encode(Message{1, Hello{1, "a", "", codec_bit(Codec::Zstd)}});
  EXPECT_EQ(std::vector<std::uint8_t>(h.begin() + kHeaderBytes, h.end()), (std::vector<std::uint8_t>{1, 0, 1, 'a', 0, 1}));
  const std::vector<std::uint8_t> data{0xAA, 0xBB};
  const auto z = encode(Message{2, WriteFramesZ{Codec::Zstd, 0x0102'0309, data}});
  EXPECT_EQ(z[3], 0x17);
  EXPECT_EQ(std::vector<std::uint8_t>(z.begin() + kHeaderBytes, z.end()),
            (std::vector<std::uint8_t>{1, 0x09, 0x03, 0x02, 0x01, 0xAA, 0xBB}));
}

TEST(Messages, WriteFramesCarriesFramesUnchangedAndWithoutCopy) {
  std::vector<std::uint8_t> frames;
  append(frames, write_frame(Reg::CLEAR, 0));
  append(frames, write_frame(Reg::FENCE, 0x42));
  const auto bytes = encode(Message{3, WriteFrames{FrameView{frames}}});
  EXPECT_TRUE(std::equal(frames.begin(), frames.end(), bytes.begin() + kHeaderBytes));
  MessageParser p;
  p.feed(bytes);
  Message m;
  ASSERT_EQ(p.next(m), MessageParser::Status::Ok);
  const auto& w = std::get<WriteFrames>(m.payload);
  ASSERT_EQ(w.frames.size(), 2u);
  EXPECT_EQ(w.frames[1], write_frame(Reg::FENCE, 0x42));
  // Zero copy: the view points into the bytes the parser buffered, not a fresh allocation.
  EXPECT_EQ(p.buffered(), 0u);
  EXPECT_TRUE(std::equal(w.frames.bytes.begin(), w.frames.bytes.end(), frames.begin()));
}

TEST(Messages, FrameDataAndReadbackLayout) {
  std::vector<std::uint8_t> px = {1, 2};
  const auto b = encode(Message{0, FrameData{7, 1, 1, PixelFormat::RGB565, 0xAABBCCDD, 5, px}});
  const std::vector<std::uint8_t> expect = {7, 0, 0, 0, 1, 0, 1, 0, 1, 0, 0xDD, 0xCC, 0xBB, 0xAA,
                                            5, 0, 0, 0, 0, 0, 0, 0, 1, 2};
  EXPECT_EQ(std::vector<std::uint8_t>(b.begin() + kHeaderBytes, b.end()), expect);
  const auto r = encode(Message{0, Readback{0x01020304, 0x10}});
  EXPECT_EQ(std::vector<std::uint8_t>(r.begin() + kHeaderBytes, r.end()),
            (std::vector<std::uint8_t>{4, 3, 2, 1, 0x10, 0, 0, 0}));
}

TEST(Messages, DecodedFieldsMatch) {
  auto s = make_samples();
  std::vector<std::uint8_t> stream;
  for (const auto& m : s.messages) encode(m, stream);
  MessageParser p;
  auto parsed = parse_all(stream, stream.size(), p);
  std::vector<Message> got;
  for (auto& x : parsed) got.push_back(x.message);  // only value fields are read below
  ASSERT_EQ(got.size(), s.messages.size());
  EXPECT_EQ(std::get<Hello>(got[0].payload).name, "viewer");
  EXPECT_EQ(std::get<Hello>(got[0].payload).token, "secret");
  EXPECT_EQ(std::get<Welcome>(got[1].payload).max_payload, 1u << 20);
  EXPECT_EQ(std::get<ErrorMsg>(got[2].payload).code, ErrorCode::NoLease);
  EXPECT_EQ(std::get<ErrorMsg>(got[2].payload).ref, 41u);
  EXPECT_EQ(std::get<RegValue>(got[8].payload).value, 0x5350'4755'0100'0000ull);
  EXPECT_TRUE(std::get<ReadbackData>(got[12].payload).last);
  EXPECT_EQ(std::get<FenceMsg>(got[13].payload).id, 0x0123'4567'89AB'CDEFull);
  EXPECT_EQ(std::get<Subscribe>(got[17].payload).max_fps, 30);
  const auto& fd = std::get<FrameData>(got[19].payload);
  EXPECT_EQ(fd.width, 3);
  EXPECT_EQ(fd.height, 2);
  EXPECT_EQ(fd.crc, 0xDEADBEEFu);
  EXPECT_EQ(fd.swap_ns, 123456789u);
  EXPECT_EQ(std::get<LeaseAcquire>(got[20].payload).mode, LeaseMode::FailIfBusy);
  EXPECT_EQ(got[24].request_id, 0xFFFFFFFFu);
}

TEST(Messages, EncodeHeaderMatchesEncode) {
  const auto full = encode(Message{42, Upload{5, std::vector<std::uint8_t>{1, 2, 3}}});
  std::uint8_t h[kHeaderBytes];
  encode_header(MsgType::Upload, 7, 42, h);
  EXPECT_TRUE(std::equal(std::begin(h), std::end(h), full.begin()));
}

TEST(Messages, NamesAreStable) {
  EXPECT_EQ(to_string(MsgType::WriteFrames), "WRITE_FRAMES");
  EXPECT_EQ(to_string(ErrorCode::BadFrame), "BAD_FRAME");
  EXPECT_EQ(static_cast<int>(ErrorCode::BadFrame), 17);
  EXPECT_TRUE(is_known_type(0x50));
  EXPECT_FALSE(is_known_type(0x07));
  EXPECT_FALSE(is_known_type(0xFF));
}

TEST(Messages, ParserCompactsSoBufferStaysBounded) {
  // 20000 small messages fed in one go, then read one by one: the buffer is compacted lazily and
  // a long stream fed in small pieces never accumulates consumed bytes.
  std::vector<std::uint8_t> one = encode(Message{1, FenceMsg{1}});
  MessageParser p;
  std::size_t parsed = 0;
  for (int i = 0; i < 20000; ++i) {
    p.feed(one);
    Message m;
    while (p.next(m) == MessageParser::Status::Ok) ++parsed;
    ASSERT_EQ(p.buffered(), 0u);
    ASSERT_LE(p.held_bytes(), one.size());  // consumed bytes are dropped, not accumulated
  }
  EXPECT_EQ(parsed, 20000u);
  EXPECT_EQ(p.stream_offset(), 20000u * one.size());

  // All at once, several times over, each time ending in half a message: the buffer holds one
  // feed plus the partial message carried over, never the consumed bytes of earlier feeds.
  std::vector<std::uint8_t> many;
  for (int i = 0; i < 20000; ++i) many.insert(many.end(), one.begin(), one.end());
  many.insert(many.end(), one.begin(), one.begin() + 7);  // the next feed completes this message
  const std::vector<std::uint8_t> rest(one.begin() + 7, one.end());
  MessageParser q;
  Message m;
  std::size_t n = 0;
  for (int round = 0; round < 5; ++round) {
    if (round > 0) q.feed(rest);
    q.feed(many);
    while (q.next(m) == MessageParser::Status::Ok) ++n;
    EXPECT_EQ(q.buffered(), 7u);
    EXPECT_LE(q.held_bytes(), 2 * many.size()) << "round " << round;
  }
  EXPECT_EQ(n, 5u * 20000 + 4);
}

TEST(Messages, MaxPayloadCanBeLowered) {
  MessageParser p(16);
  p.feed(encode(Message{1, Upload{0, std::vector<std::uint8_t>(20, 1)}}));
  Message m;
  EXPECT_EQ(p.next(m), MessageParser::Status::Error);
  EXPECT_EQ(p.error().code, ErrorCode::TooLarge);
}

}  // namespace
}  // namespace gpubridge::protocol
