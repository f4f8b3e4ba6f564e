// A single MOSI bit error on a frame the link CRC cannot protect (reads, immediate writes:
// docs/protocol.md section 4) must cost the board backend a retry, never a false "board was reset",
// a wait that ends early or a RESET that silently did not act. Each test flips one chosen bit of
// one chosen frame (bit 0 = R/W̄, bits 1..7 = index, bits 8..71 = data, MSB first); the frame
// positions follow the board backend's transfers, which the comments spell out.
#include <gtest/gtest.h>

#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "test_profiles.hpp"

namespace gpubridge::usb {
namespace {

using protocol::Reg;
using protocol::index_of;

constexpr std::uint64_t kTag = 0x0123456789ABCDEFull;

struct Bench {
  emu::EmulatedBoard board;
  BoardBackend& b() { return *board.backend; }
  std::uint64_t frames() { return board.stack->slave().frames_completed(); }
  // Flips bit `bit` of the frame `ahead` frames after the last completed one.
  void flip(std::uint64_t ahead, unsigned bit) { board.stack->spi_faults().flip_mosi_bit = (frames() + ahead) * 72 + bit; }
  // The flipped bit went over the wire (the test hit the frame it meant to).
  bool flipped() { return frames() * 72 > *board.stack->spi_faults().flip_mosi_bit; }
  std::uint64_t reg(Reg r) {
    auto v = b().read_register(index_of(r));
    EXPECT_TRUE(v) << v.error().message;
    return v ? *v : 0;
  }
};

// FT232H: the BUSY pin is waited on in the command stream, so a write batch is exactly its payload
// frames, LINK_CHECK, then LINK_STATUS, LINK_STATUS, HOST_TAG.
Bench open_bench(emu::EmulationOptions eo = {}) {
  BoardOptions bo;
  bo.host_tag = kTag;
  auto board = emu::open_emulated_board(test::profile_for(BridgeChip::FT232H, /*busy_pin=*/true), eo, bo);
  if (!board) throw std::runtime_error(board.error().message);
  return Bench{std::move(*board)};
}

Result<void> write(BoardBackend& b, std::initializer_list<protocol::Frame> frames) {
  std::vector<std::uint8_t> bytes;
  for (const auto& f : frames) protocol::append(bytes, f);
  return b.write_frames(protocol::FrameView{bytes});
}

TEST(UnprotectedFrames, LinkCheckGarbledIntoHostTagWriteIsNoReset) {
  auto t = open_bench();
  t.flip(3, 6);  // LINK_CHECK (0x14) -> HOST_TAG (0x16): HOST_TAG takes the CRC value
  auto r = write(t.b(), {protocol::write_frame(Reg::FB_DRAW, 0x1000), protocol::write_frame(Reg::CLEAR_COLOR, 0x11223344),
                         protocol::write_frame(Reg::FENCE, 7)});
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_TRUE(t.flipped());
  EXPECT_EQ(t.b().link_stats().tag_rewrites, 1u);
  EXPECT_GE(t.b().link_stats().groups_resent, 1u);  // the group lost its check and was resent
  ASSERT_TRUE(t.b().flush());
  EXPECT_EQ(t.reg(Reg::HOST_TAG), kTag);
  EXPECT_EQ(t.reg(Reg::FENCE), 7u);
  EXPECT_EQ(t.reg(Reg::CLEAR_COLOR), 0x11223344u);
}

TEST(UnprotectedFrames, HostTagReadGarbledIntoWriteKeepsTheTag) {
  auto t = open_bench();
  t.flip(5, 0);  // the batch's HOST_TAG read becomes a write of its data bits, which carry the tag
  auto r = write(t.b(), {protocol::write_frame(Reg::FB_DRAW, 0x1000), protocol::write_frame(Reg::FENCE, 9)});
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_TRUE(t.flipped());
  ASSERT_TRUE(t.b().flush());
  EXPECT_EQ(t.reg(Reg::HOST_TAG), kTag);
  EXPECT_EQ(t.reg(Reg::FENCE), 9u);
}

TEST(UnprotectedFrames, GarbledResetIsSentAgain) {
  auto t = open_bench();
  ASSERT_TRUE(write(t.b(), {protocol::write_frame(Reg::CLEAR_COLOR, 0x55), protocol::write_frame(Reg::FENCE, 3)}));
  ASSERT_TRUE(t.b().flush());
  t.flip(0, 71);  // RESET's magic loses a bit: the device ignores it (ERR_BAD_VALUE)
  auto r = t.b().reset();
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_TRUE(t.flipped());
  EXPECT_EQ(t.b().link_stats().reset_retries, 1u);
  EXPECT_EQ(t.reg(Reg::CLEAR_COLOR), protocol::describe(Reg::CLEAR_COLOR).reset);
  EXPECT_EQ(t.reg(Reg::FENCE), 0u);
  EXPECT_EQ(t.reg(Reg::STATUS) >> 48, 0u) << "the second RESET cleared the first one's ERR_BAD_VALUE";
  EXPECT_EQ(t.reg(Reg::HOST_TAG), kTag);
}

// A queued frame can be garbled into an immediate one too: PRIM (0x03) with TYPE LIST becomes a
// LINK_CTRL (0x13) write of 0. Before protocol 1.3 that switched strict mode off: the writes held
// ahead of it in the first group were discarded, the rest of the batch executed unchecked, and the
// second group's check matched, so the host counted the first group as accepted and lost its
// writes. Since 1.3 leaving strict mode takes LINK_CTRL.CLEAR_KEY: the write is refused
// (ERR_BAD_VALUE), the first group fails its check and the whole batch is resent.
TEST(UnprotectedFrames, PrimGarbledIntoLinkCtrlLeavesStrictModeOn) {
  auto t = open_bench();
  std::vector<std::uint8_t> bytes;
  protocol::append(bytes, protocol::write_frame(Reg::CLEAR_COLOR, 0x11223344));
  for (int i = 1; i < 40; ++i)  // 40 payload frames: groups of 32 and 8
    protocol::append(bytes, i == 5 ? protocol::write_frame(Reg::PRIM, 0) : protocol::write_frame(Reg::FENCE, static_cast<std::uint64_t>(i)));
  t.flip(5, 3);  // index bit 4 of PRIM: 0x03 -> 0x13
  auto r = t.b().write_frames(protocol::FrameView{bytes});
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_TRUE(t.flipped());
  EXPECT_EQ(t.b().link_stats().groups_resent, 2u) << "the first group failed its check, the second was discarded";
  ASSERT_TRUE(t.b().flush());
  EXPECT_EQ(t.reg(Reg::CLEAR_COLOR), 0x11223344u) << "the first group's writes were lost";
  EXPECT_EQ(t.reg(Reg::FENCE), 39u);
  EXPECT_EQ(t.reg(Reg::LINK_CTRL), 1u);
  EXPECT_EQ((t.reg(Reg::STATUS) >> 48) & protocol::ERR_BAD_VALUE, protocol::ERR_BAD_VALUE) << "the garbled LINK_CTRL was refused";
}

// After RESET: RESET, HOST_TAG read, then attach: ID, ID, CAPS, CAPS, CAPS2, CAPS2 (protocol 1.4),
// HOST_TAG write, HOST_TAG read.
TEST(UnprotectedFrames, GarbledIdReadAfterResetIsReadAgain) {
  auto t = open_bench();
  t.flip(2, 6);  // ID (0x7F) -> 0x7D, CAPS2 since protocol 1.4: reads 1, not the ID
  auto r = t.b().reset();
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_TRUE(t.flipped());
  EXPECT_EQ(t.reg(Reg::HOST_TAG), kTag);
}

TEST(UnprotectedFrames, GarbledHostTagEchoIsWrittenAgain) {
  auto t = open_bench();
  t.flip(8, 40);  // a data bit of the HOST_TAG write
  auto r = t.b().reset();
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_TRUE(t.flipped());
  EXPECT_EQ(t.reg(Reg::HOST_TAG), kTag);
}

// A device that executes one queued command per frame it receives: after the writes the FIFO is
// still full, and flush polls. Its first STATUS read turned into a write of STATUS returns 0 on
// MISO, which a single read would take for an idle device.
TEST(UnprotectedFrames, GarbledStatusReadDoesNotEndAWait) {
  emu::EmulationOptions eo;
  eo.drain_per_frame = 1;
  eo.use_simulator = false;
  auto t = open_bench(eo);
  std::vector<std::uint8_t> bytes;
  for (int i = 0; i < 60; ++i) protocol::append(bytes, protocol::write_frame(Reg::FENCE, static_cast<std::uint64_t>(i)));
  ASSERT_TRUE(t.b().write_frames(protocol::FrameView{bytes}));
  t.flip(0, 0);
  ASSERT_TRUE(t.b().flush());
  ASSERT_TRUE(t.flipped());
  // FENCE is read before another frame lets the device execute anything
  const auto fence = t.b().read_register(index_of(Reg::FENCE));
  ASSERT_TRUE(fence);
  EXPECT_EQ(*fence, 59u) << "flush returned while commands were still queued";
}

}  // namespace
}  // namespace gpubridge::usb
