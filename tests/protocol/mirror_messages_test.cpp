// SUBSCRIBE's source selector and FRAME's source byte (mirror mode, docs/protocol.md 17.3): the
// additions leave every old message byte-identical and decode old messages exactly as before.
#include <gtest/gtest.h>

#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::protocol {
namespace {

std::vector<std::uint8_t> payload_of(const std::vector<std::uint8_t>& wire) {
  return {wire.begin() + static_cast<std::ptrdiff_t>(kHeaderBytes), wire.end()};
}

std::vector<std::uint8_t> with_header(MsgType t, const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> out(kHeaderBytes);
  encode_header(t, static_cast<std::uint32_t>(payload.size()), 9, out.data());
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

MessageParser::Status parse(const std::vector<std::uint8_t>& wire, Message& out, DecodeError& err) {
  MessageParser p;
  p.feed(wire);
  const auto st = p.next(out);
  if (st == MessageParser::Status::Error) err = p.error();
  return st;
}

TEST(MirrorMessages, SubscribeWithoutSourceKeepsTheOriginalThreeBytes) {
  const auto wire = encode(Message{1, Subscribe{FrameFormat::RGB565, 30}});
  EXPECT_EQ(payload_of(wire), (std::vector<std::uint8_t>{2, 30, 0}));
  // An explicit board source is the 4-byte form (re-encoding a decoded message gives its bytes back).
  const auto explicit_board = encode(Message{1, Subscribe{FrameFormat::RGB565, 30, FrameSource::Board}});
  EXPECT_EQ(payload_of(explicit_board), (std::vector<std::uint8_t>{2, 30, 0, 0}));
}

TEST(MirrorMessages, SimAndDiffSubscribeAppendTheSourceByte) {
  EXPECT_EQ(payload_of(encode(Message{1, Subscribe{FrameFormat::Native, 0, FrameSource::Sim}})),
            (std::vector<std::uint8_t>{0, 0, 0, 1}));
  EXPECT_EQ(payload_of(encode(Message{1, Subscribe{FrameFormat::RGBA8888, 500, FrameSource::Diff}})),
            (std::vector<std::uint8_t>{1, 0xF4, 0x01, 2}));
}

TEST(MirrorMessages, SubscribeDecodesOldAndNewForms) {
  Message m;
  DecodeError e{ErrorCode::Internal, {}};
  ASSERT_EQ(parse(with_header(MsgType::Subscribe, {1, 10, 0}), m, e), MessageParser::Status::Ok);
  EXPECT_FALSE(std::get<Subscribe>(m.payload).source.has_value()) << "3 bytes: no source (board)";
  EXPECT_EQ(std::get<Subscribe>(m.payload).max_fps, 10);
  for (std::uint8_t s : {0, 1, 2}) {
    const auto wire = with_header(MsgType::Subscribe, {1, 10, 0, s});
    ASSERT_EQ(parse(wire, m, e), MessageParser::Status::Ok) << int(s);
    ASSERT_TRUE(std::get<Subscribe>(m.payload).source.has_value());
    EXPECT_EQ(static_cast<int>(*std::get<Subscribe>(m.payload).source), s);
    std::vector<std::uint8_t> re = encode(m);
    EXPECT_EQ(re, wire) << "decoded SUBSCRIBE re-encodes to its own bytes";
  }
}

TEST(MirrorMessages, BadSourceOrTrailingBytesAreMalformed) {
  Message m;
  DecodeError e{ErrorCode::Internal, {}};
  ASSERT_EQ(parse(with_header(MsgType::Subscribe, {0, 0, 0, 3}), m, e), MessageParser::Status::Error);
  EXPECT_EQ(e.code, ErrorCode::Malformed);
  EXPECT_NE(e.message.find("SUBSCRIBE source 3 is not 0 (board), 1 (sim) or 2 (diff) (payload byte 3)"),
            std::string::npos)
      << e.message;
  ASSERT_EQ(parse(with_header(MsgType::Subscribe, {0, 0, 0, 1, 0}), m, e), MessageParser::Status::Error);
  EXPECT_EQ(e.code, ErrorCode::Malformed);
  EXPECT_NE(e.message.find("trailing"), std::string::npos) << e.message;
}

TEST(MirrorMessages, FrameCarriesItsSourceInByteNine) {
  const std::vector<std::uint8_t> px = {1, 2, 3, 4};
  FrameData board{7, 1, 1, PixelFormat::RGBA8888, 0xAABBCCDD, 5, px};
  const auto old_wire = encode(Message{0, board});
  EXPECT_EQ(payload_of(old_wire)[9], 0) << "board frames keep the former reserved 0";
  FrameData diff = board;
  diff.source = FrameSource::Diff;
  const auto wire = encode(Message{0, diff});
  EXPECT_EQ(payload_of(wire)[9], 2);
  Message m;
  DecodeError e{ErrorCode::Internal, {}};
  ASSERT_EQ(parse(wire, m, e), MessageParser::Status::Ok);
  EXPECT_EQ(std::get<FrameData>(m.payload).source, FrameSource::Diff);
  ASSERT_EQ(parse(old_wire, m, e), MessageParser::Status::Ok);
  EXPECT_EQ(std::get<FrameData>(m.payload).source, FrameSource::Board);

  auto bad = payload_of(wire);
  bad[9] = 3;
  ASSERT_EQ(parse(with_header(MsgType::FrameMsg, bad), m, e), MessageParser::Status::Error);
  EXPECT_NE(e.message.find("FRAME source 3"), std::string::npos) << e.message;
}

TEST(MirrorMessages, NamesOfSourcesAndTheNewErrorCode) {
  for (auto s : {FrameSource::Board, FrameSource::Sim, FrameSource::Diff})
    EXPECT_EQ(parse_frame_source(to_string(s)), s);
  EXPECT_FALSE(parse_frame_source("model"));
  EXPECT_EQ(to_string(ErrorCode::Unavailable), "UNAVAILABLE");
  EXPECT_EQ(static_cast<int>(ErrorCode::Unavailable), 18);
}

}  // namespace
}  // namespace gpubridge::protocol
