// Every class of malformed socket input becomes an error value with the right stable code and a
// message naming what and where; nothing is allocated for lengths that are refused.
#include <gtest/gtest.h>

#include "gpubridge/protocol/messages.hpp"
#include "message_samples.hpp"

namespace gpubridge::protocol {
namespace {

std::vector<std::uint8_t> raw(std::uint8_t type, std::vector<std::uint8_t> payload, std::uint32_t length_override = 0,
                              bool use_override = false) {
  std::vector<std::uint8_t> out(kHeaderBytes);
  encode_header(static_cast<MsgType>(type), use_override ? length_override : static_cast<std::uint32_t>(payload.size()),
                7, out.data());
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

struct Outcome {
  MessageParser::Status status;
  DecodeError error;
};
Outcome parse_one(std::span<const std::uint8_t> bytes) {
  MessageParser p;
  p.feed(bytes);
  Message m;
  auto st = p.next(m);
  return {st, p.error()};
}

void expect_error(std::span<const std::uint8_t> bytes, ErrorCode code, const std::string& needle) {
  const auto o = parse_one(bytes);
  ASSERT_EQ(o.status, MessageParser::Status::Error);
  EXPECT_EQ(o.error.code, code) << o.error.message;
  EXPECT_NE(o.error.message.find(needle), std::string::npos) << "message: " << o.error.message;
}

std::vector<std::uint8_t> le32(std::uint32_t v) {
  return {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8), static_cast<std::uint8_t>(v >> 16),
          static_cast<std::uint8_t>(v >> 24)};
}

// Found by the binary-trace fuzzer: the socket/binary path accepted an UPLOAD wrapping past 4 GiB
// that the text trace refuses. Address ranges are checked where the message is decoded.
TEST(ParserMalformed, CompressedWritesNameTheirBadField) {
  const auto z = [](std::uint8_t codec, std::uint32_t frames_bytes, std::vector<std::uint8_t> data) {
    std::vector<std::uint8_t> p{codec};
    for (int i = 0; i < 4; ++i) p.push_back(static_cast<std::uint8_t>(frames_bytes >> (8 * i)));
    p.insert(p.end(), data.begin(), data.end());
    return raw(static_cast<std::uint8_t>(MsgType::WriteFramesZ), p);
  };
  expect_error(z(2, 9, {1}), ErrorCode::Malformed, "codec 2 is not a known codec");
  expect_error(z(1, 10, {1}), ErrorCode::Malformed, "frames_bytes 10 is not a WRITE_FRAMES payload size");
  expect_error(z(1, 0, {1}), ErrorCode::Malformed, "frames_bytes 0");
  expect_error(z(1, 9, {}), ErrorCode::Malformed, "data is empty (payload byte 5)");
  // HELLO: one optional codecs byte, no more.
  std::vector<std::uint8_t> hello{1, 0, 1, 'a', 0, 1, 0};
  expect_error(raw(static_cast<std::uint8_t>(MsgType::Hello), hello), ErrorCode::Malformed, "1 unexpected trailing bytes");
}

TEST(ParserMalformed, Dmc1WordsAreWholeWords) {
  const auto words = [](std::size_t n) { return raw(static_cast<std::uint8_t>(MsgType::Dmc1Words), std::vector<std::uint8_t>(n, 0x5A)); };
  expect_error(words(0), ErrorCode::Malformed, "DMC1_WORDS words are empty; send at least one 8-byte command word");
  expect_error(words(12), ErrorCode::Malformed, "DMC1_WORDS words of 12 bytes are not whole 8-byte command words");
  const auto ok = parse_one(words(16));
  ASSERT_EQ(ok.status, MessageParser::Status::Ok) << ok.error.message;
}

TEST(ParserMalformed, Dmc1WordsAreLittleEndian) {
  const std::vector<std::uint64_t> w{0x0102'0304'0506'0708ull, 0xFFEE'DDCC'BBAA'9988ull};
  std::vector<std::uint8_t> bytes;
  append_dmc1_words(w, bytes);
  ASSERT_EQ(bytes.size(), 16u);
  EXPECT_EQ(bytes[0], 0x08);
  EXPECT_EQ(bytes[7], 0x01);
  EXPECT_EQ(dmc1_words_of(bytes), w);
  const Dmc1Words m{bytes};
  EXPECT_EQ(m.size(), 2u);
  EXPECT_EQ(m.word(1), w[1]);
  EXPECT_EQ(to_string(ErrorCode::WrongDevice), "WRONG_DEVICE");
  EXPECT_EQ(static_cast<int>(ErrorCode::WrongDevice), 19);
}

TEST(ParserMalformed, UploadAndReadbackMayNotWrapPast4GiB) {
  auto upload = encode(Message{7, Upload{0xFFFFFFFFu, std::span<const std::uint8_t>(le32(0x1234).data(), 2)}});
  expect_error(upload, ErrorCode::Malformed, "run past the 4 GiB address space");
  auto edge = encode(Message{7, Upload{0xFFFFFFFEu, std::span<const std::uint8_t>(le32(0x1234).data(), 2)}});
  EXPECT_EQ(parse_one(edge).status, MessageParser::Status::Ok) << "the last two bytes of the address space are legal";
  expect_error(encode(Message{8, Readback{0xFFFFFF00u, 0x101}}), ErrorCode::Malformed, "run past the 4 GiB");
  EXPECT_EQ(parse_one(encode(Message{8, Readback{0xFFFFFF00u, 0x100}})).status, MessageParser::Status::Ok);
}

TEST(ParserMalformed, TruncatedAtEveryByteNeedsMore) {
  auto s = testing::make_samples();
  for (const auto& m : s.messages) {
    const auto bytes = encode(m);
    for (std::size_t cut = 0; cut < bytes.size(); ++cut) {
      MessageParser p;
      p.feed(std::span(bytes).first(cut));
      Message out;
      ASSERT_EQ(p.next(out), MessageParser::Status::NeedMore) << to_string(type_of(m.payload)) << " cut " << cut;
    }
  }
}

TEST(ParserMalformed, ShortPayloadOfFixedSizeTypesIsMalformed) {
  auto s = testing::make_samples();
  for (const auto& m : s.messages) {
    const auto bytes = encode(m);
    const std::vector<std::uint8_t> payload(bytes.begin() + kHeaderBytes, bytes.end());
    for (std::size_t len = 0; len < payload.size(); ++len) {
      const auto t = static_cast<std::uint8_t>(type_of(m.payload));
      const auto o = parse_one(raw(t, {payload.begin(), payload.begin() + static_cast<std::ptrdiff_t>(len)}));
      // A shorter payload is either still valid (variable-length fields) or Malformed; never
      // anything else, never a crash (ASan/UBSan builds run this too).
      if (o.status == MessageParser::Status::Error) {
        EXPECT_EQ(o.error.code, ErrorCode::Malformed) << o.error.message;
        EXPECT_NE(o.error.message.find(std::string(to_string(type_of(m.payload)))), std::string::npos);
      } else {
        EXPECT_EQ(o.status, MessageParser::Status::Ok);
      }
      switch (type_of(m.payload)) {
        case MsgType::Fence: case MsgType::FenceDone: case MsgType::ReadReg: case MsgType::RegValue:
        case MsgType::UploadAck: case MsgType::Readback: case MsgType::Subscribe: case MsgType::LeaseAcquire:
        case MsgType::LeaseGranted: case MsgType::FrameMsg:
          EXPECT_EQ(o.status, MessageParser::Status::Error) << to_string(type_of(m.payload)) << " len " << len;
          break;
        case MsgType::Hello:
          // Without its optional last byte (codecs), a HELLO is the original form, still valid.
          if (!(std::get<Hello>(m.payload).codecs && len + 1 == payload.size())) {
            EXPECT_EQ(o.status, MessageParser::Status::Error) << "HELLO len " << len;
          }
          break;
        default: break;
      }
    }
  }
}

TEST(ParserMalformed, FourGiBLengthIsRefusedWithoutAllocating) {
  auto bytes = raw(static_cast<std::uint8_t>(MsgType::Upload), {}, 0xFFFFFFFFu, true);
  MessageParser p;
  p.feed(bytes);
  Message m;
  ASSERT_EQ(p.next(m), MessageParser::Status::Error);
  EXPECT_EQ(p.error().code, ErrorCode::TooLarge);
  EXPECT_NE(p.error().message.find("4294967295"), std::string::npos) << p.error().message;
  EXPECT_LE(p.held_bytes(), kHeaderBytes);
  // Only the first 8 bytes are needed to refuse it.
  MessageParser early;
  early.feed(std::span(bytes).first(8));
  EXPECT_EQ(early.next(m), MessageParser::Status::Error);
  EXPECT_EQ(early.error().code, ErrorCode::TooLarge);
}

TEST(ParserMalformed, OversizedJustOverTheLimit) {
  MessageParser p(1000);
  p.feed(raw(static_cast<std::uint8_t>(MsgType::Upload), {}, 1001, true));
  Message m;
  EXPECT_EQ(p.next(m), MessageParser::Status::Error);
  EXPECT_EQ(p.error().code, ErrorCode::TooLarge);
  MessageParser ok(1000);
  ok.feed(raw(static_cast<std::uint8_t>(MsgType::Upload), std::vector<std::uint8_t>(1000, 1)));
  EXPECT_EQ(ok.next(m), MessageParser::Status::Ok);
}

TEST(ParserMalformed, BadMagicDetectedFromTheFirstByte) {
  expect_error(std::vector<std::uint8_t>{'G', 'X', 1, 0x04, 0, 0, 0, 0, 0, 0, 0, 0}, ErrorCode::BadMagic, "magic");
  const std::string http = "GET / HTTP/1.1\r\n";  // 'G' matches; 'E' does not
  expect_error(std::span(reinterpret_cast<const std::uint8_t*>(http.data()), 2), ErrorCode::BadMagic, "magic");
  expect_error(std::vector<std::uint8_t>{0x16}, ErrorCode::BadMagic, "0x16");  // a TLS ClientHello
}

TEST(ParserMalformed, BadVersion) {
  auto b = raw(static_cast<std::uint8_t>(MsgType::Ping), {});
  b[2] = 2;
  expect_error(b, ErrorCode::BadVersion, "version 2");
  expect_error(std::span(b).first(3), ErrorCode::BadVersion, "version 2");
}

TEST(ParserMalformed, UnknownType) {
  expect_error(raw(0x07, {}), ErrorCode::UnknownType, "0x07");
  expect_error(raw(0xFF, {}), ErrorCode::UnknownType, "0xFF");
}

TEST(ParserMalformed, WriteFramesShapes) {
  std::vector<std::uint8_t> prefix = encode(Message{1, FenceMsg{1}});  // 20 bytes before the bad message
  auto bad = raw(static_cast<std::uint8_t>(MsgType::WriteFrames), std::vector<std::uint8_t>(10, 0));
  prefix.insert(prefix.end(), bad.begin(), bad.end());
  MessageParser p;
  p.feed(prefix);
  Message m;
  ASSERT_EQ(p.next(m), MessageParser::Status::Ok);
  ASSERT_EQ(p.next(m), MessageParser::Status::Error);
  EXPECT_EQ(p.error().code, ErrorCode::Malformed);
  EXPECT_EQ(p.error().message, "WRITE_FRAMES payload of 10 bytes is not a multiple of 9 (stream offset 20)");
  expect_error(raw(static_cast<std::uint8_t>(MsgType::WriteFrames), {}), ErrorCode::Malformed, "empty");
}

TEST(ParserMalformed, WriteFramesWithReadBitIsBadFrame) {
  std::vector<std::uint8_t> frames;
  for (int i = 0; i < 3; ++i) append(frames, write_frame(Reg::CLEAR, 0));
  append(frames, read_frame(Reg::STATUS));
  expect_error(raw(static_cast<std::uint8_t>(MsgType::WriteFrames), frames), ErrorCode::BadFrame,
               "frame 3 (payload byte 27) has the read bit set; use READ_REG");
}

TEST(ParserMalformed, FieldLimits) {
  const auto T = [](MsgType t) { return static_cast<std::uint8_t>(t); };
  // Hello: name 65 bytes, token 129 bytes.
  std::vector<std::uint8_t> hello = {1, 0, 65};
  hello.insert(hello.end(), 65, 'n');
  hello.push_back(0);
  expect_error(raw(T(MsgType::Hello), hello), ErrorCode::Malformed, "name_len 65 exceeds 64");
  std::vector<std::uint8_t> hello2 = {1, 0, 1, 'n', 129};
  hello2.insert(hello2.end(), 129, 't');
  expect_error(raw(T(MsgType::Hello), hello2), ErrorCode::Malformed, "token_len 129 exceeds 128");
  // Readback length 0 and 64 MiB + 1.
  auto rb = le32(0);
  auto len0 = le32(0);
  rb.insert(rb.end(), len0.begin(), len0.end());
  expect_error(raw(T(MsgType::Readback), rb), ErrorCode::Malformed, "length 0");
  rb = le32(0);
  auto big = le32((64u << 20) + 1);
  rb.insert(rb.end(), big.begin(), big.end());
  expect_error(raw(T(MsgType::Readback), rb), ErrorCode::Malformed, "67108865");
  // Subscribe format 4, LeaseAcquire mode 2.
  expect_error(raw(T(MsgType::Subscribe), {4, 0, 0}), ErrorCode::Malformed, "format 4");
  expect_error(raw(T(MsgType::LeaseAcquire), {2}), ErrorCode::Malformed, "mode 2");
  // ReadReg index beyond 7 bits; trailing bytes.
  expect_error(raw(T(MsgType::ReadReg), {0x80}), ErrorCode::Malformed, "index 128");
  expect_error(raw(T(MsgType::Fence), {1, 2, 3, 4, 5, 6, 7, 8, 9}), ErrorCode::Malformed, "trailing");
  // Ping over 64 bytes; Upload without data.
  expect_error(raw(T(MsgType::Ping), std::vector<std::uint8_t>(65, 0)), ErrorCode::Malformed, "65 bytes");
  expect_error(raw(T(MsgType::Upload), le32(5)), ErrorCode::Malformed, "empty");
}

TEST(ParserMalformed, PixelAndChunkSizes) {
  const auto T = [](MsgType t) { return static_cast<std::uint8_t>(t); };
  // FRAME 2x2 RGBA8888 needs 16 pixel bytes; give 15.
  std::vector<std::uint8_t> f = {1, 0, 0, 0, 2, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  f.insert(f.end(), 15, 0);
  expect_error(raw(T(MsgType::FrameMsg), f), ErrorCode::Malformed, "16 bytes");
  f.push_back(0);
  EXPECT_EQ(parse_one(raw(T(MsgType::FrameMsg), f)).status, MessageParser::Status::Ok);
  f[8] = 3;  // pixel format 3 does not exist
  expect_error(raw(T(MsgType::FrameMsg), f), ErrorCode::Malformed, "format 3");
  // READBACK_DATA: last must be 0/1, data at most 64 KiB.
  std::vector<std::uint8_t> rd = {0, 0, 0, 0, 2, 1};
  expect_error(raw(T(MsgType::ReadbackData), rd), ErrorCode::Malformed, "last 2");
  rd = {0, 0, 0, 0, 1};
  rd.insert(rd.end(), kMaxReadbackChunk + 1, 0);
  expect_error(raw(T(MsgType::ReadbackData), rd), ErrorCode::Malformed, "65537");
}

TEST(ParserMalformed, JsonPayloadsMustBeObjects) {
  const auto T = static_cast<std::uint8_t>(MsgType::StatusReply);
  const auto text = [](std::string s) { return std::vector<std::uint8_t>(s.begin(), s.end()); };
  expect_error(raw(T, text("{\"a\":")), ErrorCode::Malformed, "not valid");
  expect_error(raw(T, text("[1,2]")), ErrorCode::Malformed, "not an object");
  expect_error(raw(T, text("{\"a\":\"\xff\"}")), ErrorCode::Malformed, "not valid");
  expect_error(raw(T, text(std::string(100, '[') + std::string(100, ']'))), ErrorCode::Malformed, "nested");
  EXPECT_EQ(parse_one(raw(T, text("{\"ok\":[1,{\"b\":null}]}"))).status, MessageParser::Status::Ok);
  // Error text must be UTF-8.
  std::vector<std::uint8_t> err = {5, 0, 0, 0, 0, 0, 0xC0, 0x80};  // overlong NUL
  expect_error(raw(static_cast<std::uint8_t>(MsgType::Error), err), ErrorCode::Malformed, "UTF-8");
}

TEST(ParserMalformed, ErrorPoisonsTheParser) {
  MessageParser p;
  p.feed(raw(0x07, {}));
  Message m;
  ASSERT_EQ(p.next(m), MessageParser::Status::Error);
  const std::string first = p.error().message;
  p.feed(encode(Message{1, Bye{}}));
  EXPECT_EQ(p.next(m), MessageParser::Status::Error);
  EXPECT_EQ(p.error().message, first);
  EXPECT_EQ(p.held_bytes(), 0u);  // a poisoned parser keeps nothing
}

}  // namespace
}  // namespace gpubridge::protocol
