// MessageParser's direct-read API (prepare/commit): the same messages as feed(), reads that stop
// at the end of a large message so the buffer is reused in place, and no allocation sized by a
// header that fails its checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "gpubridge/protocol/messages.hpp"
#include "message_samples.hpp"

namespace gpubridge::protocol {
namespace {

// Copies `bytes` into the parser through prepare/commit, at most `chunk` per read (like a socket
// read), parsing after every read. Returns each message re-encoded at once (spans die on prepare).
std::vector<std::vector<std::uint8_t>> read_all(std::span<const std::uint8_t> bytes, std::size_t chunk, MessageParser& p) {
  std::vector<std::vector<std::uint8_t>> out;
  std::size_t at = 0;
  while (at < bytes.size()) {
    const auto space = p.prepare(chunk);
    EXPECT_GE(space.size(), 1u);
    EXPECT_LE(space.size(), chunk);
    if (space.empty()) break;
    const std::size_t n = std::min(space.size(), bytes.size() - at);
    std::memcpy(space.data(), bytes.data() + at, n);
    p.commit(n);
    at += n;
    Message m;
    MessageParser::Status st;
    while ((st = p.next(m)) == MessageParser::Status::Ok) out.push_back(encode(m));
    EXPECT_NE(st, MessageParser::Status::Error) << p.error().message;
  }
  return out;
}

std::vector<std::uint8_t> write_frames_message(std::size_t frames, std::uint32_t request_id) {
  std::vector<std::uint8_t> payload;
  for (std::size_t i = 0; i < frames; ++i) append(payload, write_frame(Reg::COLOR, 0x0102030405060708ull + i));
  return encode(Message{request_id, WriteFrames{FrameView{payload}}});
}

TEST(ParserDirectRead, EveryTypeArrivesAsSentAtAnyReadSize) {
  auto s = testing::make_samples();
  std::vector<std::uint8_t> stream;
  for (const auto& m : s.messages) encode(m, stream);
  for (std::size_t chunk : {std::size_t{1}, std::size_t{7}, std::size_t{64}, std::size_t{1} << 20}) {
    MessageParser p;
    const auto got = read_all(stream, chunk, p);
    ASSERT_EQ(got.size(), s.messages.size()) << "chunk " << chunk;
    for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], encode(s.messages[i])) << "chunk " << chunk << " #" << i;
    EXPECT_EQ(p.buffered(), 0u);
    EXPECT_EQ(p.stream_offset(), stream.size());
  }
}

TEST(ParserDirectRead, MixesWithFeed) {
  auto s = testing::make_samples();
  std::vector<std::uint8_t> stream;
  for (const auto& m : s.messages) encode(m, stream);
  MessageParser p;
  std::size_t at = 0, parsed = 0;
  for (bool direct = false; at < stream.size(); direct = !direct) {
    const std::size_t n = std::min<std::size_t>(13, stream.size() - at);
    if (direct) {
      const auto space = p.prepare(n);
      ASSERT_EQ(space.size(), n);  // small messages: no reason to stop short
      std::memcpy(space.data(), stream.data() + at, n);
      p.commit(n);
    } else {
      p.feed(std::span(stream).subspan(at, n));
    }
    at += n;
    Message m;
    while (p.next(m) == MessageParser::Status::Ok) {
      ASSERT_LT(parsed, s.messages.size());
      EXPECT_EQ(encode(m), encode(s.messages[parsed]));
      ++parsed;
    }
  }
  EXPECT_EQ(parsed, s.messages.size());
}

TEST(ParserDirectRead, ReadStopsAtTheEndOfALargeMessage) {
  const auto big = write_frames_message(4000, 7);  // 36012 bytes, above kLargeMessageBytes
  ASSERT_GE(big.size(), MessageParser::kLargeMessageBytes);
  MessageParser p;
  auto space = p.prepare(1000);
  ASSERT_EQ(space.size(), 1000u);
  std::memcpy(space.data(), big.data(), 1000);
  p.commit(1000);
  Message m;
  ASSERT_EQ(p.next(m), MessageParser::Status::NeedMore);
  // The header is known now: a 1 MiB read would be offered only what the message still lacks.
  space = p.prepare(1u << 20);
  ASSERT_EQ(space.size(), big.size() - 1000);
  std::memcpy(space.data(), big.data() + 1000, space.size());
  p.commit(space.size());
  ASSERT_EQ(p.next(m), MessageParser::Status::Ok);
  EXPECT_EQ(encode(m), big);
}

TEST(ParserDirectRead, LargeMessagesReuseTheBufferInPlace) {
  // A stream of large messages read with the daemon's read size: each message is complete at the
  // end of the buffer, so every one lands at the same address (nothing moved, nothing regrown).
  std::vector<std::uint8_t> stream;
  for (std::uint32_t id = 1; id <= 6; ++id) {
    const auto one = write_frames_message(116508, id);  // ~1 MiB, slightly more than one read
    stream.insert(stream.end(), one.begin(), one.end());
  }
  MessageParser p;
  std::vector<const std::uint8_t*> starts;
  std::size_t at = 0, held_after_first = 0;
  while (at < stream.size()) {
    const auto space = p.prepare(1u << 20);
    ASSERT_FALSE(space.empty());
    const std::size_t n = std::min(space.size(), stream.size() - at);
    std::memcpy(space.data(), stream.data() + at, n);
    p.commit(n);
    at += n;
    Message m;
    while (p.next(m) == MessageParser::Status::Ok) {
      const auto& frames = std::get<WriteFrames>(m.payload).frames;
      EXPECT_EQ(m.request_id, starts.size() + 1);
      starts.push_back(frames.bytes.data());
      if (starts.size() == 1) held_after_first = p.held_bytes();
    }
  }
  ASSERT_EQ(starts.size(), 6u);
  for (const auto* s : starts) EXPECT_EQ(s, starts.front());
  EXPECT_EQ(p.held_bytes(), held_after_first);
}

TEST(ParserDirectRead, SmallMessagesShareOneRead) {
  std::vector<std::uint8_t> stream;
  for (std::uint32_t id = 1; id <= 100; ++id) encode(Message{id, FenceMsg{id}}, stream);  // 20 bytes each
  MessageParser p;
  const auto space = p.prepare(4096);
  ASSERT_EQ(space.size(), 4096u);
  std::memcpy(space.data(), stream.data(), stream.size());
  p.commit(stream.size());
  Message m;
  std::uint64_t expect = 1;
  while (p.next(m) == MessageParser::Status::Ok) EXPECT_EQ(std::get<FenceMsg>(m.payload).id, expect++);
  EXPECT_EQ(expect, 101u);
}

TEST(ParserDirectRead, HeaderBeyondTheLimitSizesNothing) {
  // A header announcing more than max_payload must not make prepare() allocate for it.
  MessageParser p(1000);
  std::uint8_t header[kHeaderBytes];
  encode_header(MsgType::Upload, 15u << 20, 1, header);
  auto space = p.prepare(kHeaderBytes);
  std::memcpy(space.data(), header, kHeaderBytes);
  p.commit(kHeaderBytes);
  space = p.prepare(64);
  EXPECT_LE(space.size(), 64u);
  EXPECT_LE(p.held_bytes(), kHeaderBytes + 1000 + 64);
  Message m;
  ASSERT_EQ(p.next(m), MessageParser::Status::Error);
  EXPECT_EQ(p.error().code, ErrorCode::TooLarge);
  // Poisoned: no more space is handed out and commits change nothing.
  EXPECT_TRUE(p.prepare(4096).empty());
  p.commit(4096);
  EXPECT_EQ(p.buffered(), 0u);
  EXPECT_EQ(p.next(m), MessageParser::Status::Error);
}

TEST(ParserDirectRead, ValidHugeHeaderGrowsOnlyByTheReadSize) {
  // A legal 16 MiB message: the buffer follows the bytes that actually arrive, not the header.
  MessageParser p;
  std::uint8_t header[kHeaderBytes];
  encode_header(MsgType::Upload, kMaxPayload, 1, header);
  auto space = p.prepare(4096);
  std::memcpy(space.data(), header, kHeaderBytes);
  p.commit(kHeaderBytes);
  Message m;
  ASSERT_EQ(p.next(m), MessageParser::Status::NeedMore);
  space = p.prepare(4096);
  EXPECT_EQ(space.size(), 4096u);
  EXPECT_LE(p.held_bytes(), 2u * 4096 + kHeaderBytes);
}

TEST(ParserDirectRead, CommitIsClampedToThePreparedSpan) {
  MessageParser p;
  const auto fence = encode(Message{5, FenceMsg{9}});
  auto space = p.prepare(fence.size());
  std::memcpy(space.data(), fence.data(), fence.size());
  p.commit(fence.size() + 1000);  // a caller bug must not expose uninitialised bytes
  EXPECT_EQ(p.buffered(), fence.size());
  p.commit(10);  // nothing prepared since the last commit
  EXPECT_EQ(p.buffered(), fence.size());
  Message m;
  ASSERT_EQ(p.next(m), MessageParser::Status::Ok);
  EXPECT_EQ(std::get<FenceMsg>(m.payload).id, 9u);
  EXPECT_EQ(p.next(m), MessageParser::Status::NeedMore);
}

TEST(ParserDirectRead, ZeroSizedPrepareIsEmpty) {
  MessageParser p;
  EXPECT_TRUE(p.prepare(0).empty());
  EXPECT_EQ(p.held_bytes(), 0u);
}

}  // namespace
}  // namespace gpubridge::protocol
