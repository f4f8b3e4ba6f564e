// BoardBackend end to end through each emulated bridge chip: attach, burst writes, flow
// control, strict link integrity with resend, upload/readback, scanout.
#include <gtest/gtest.h>

#include <random>

#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "test_profiles.hpp"

namespace gpubridge::usb {
namespace {

using protocol::Reg;

std::vector<std::uint8_t> pattern(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<std::uint8_t> v(n);
  for (auto& b : v) b = static_cast<std::uint8_t>(rng());
  return v;
}

class BoardEndToEnd : public ::testing::TestWithParam<BridgeChip> {};

TEST_P(BoardEndToEnd, AttachUploadReadbackAndNoModelViolations) {
  auto board = emu::open_emulated_board(test::profile_for(GetParam()));
  ASSERT_TRUE(board) << board.error().message;
  auto& b = *board->backend;
  EXPECT_EQ(b.info().id >> 32, protocol::kIdMagic);
  EXPECT_TRUE(b.strict_link());
  const auto data = pattern(1000, 7);
  ASSERT_TRUE(b.upload(4096, data));
  auto back = b.readback(4096, 1000);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(*back, data);
  // Unaligned readback slices the right bytes.
  auto mid = b.readback(4096 + 13, 100);
  ASSERT_TRUE(mid);
  EXPECT_TRUE(std::equal(mid->begin(), mid->end(), data.begin() + 13));
  const auto v = board->stack->violations();
  EXPECT_TRUE(v.empty()) << v.front();
}

TEST_P(BoardEndToEnd, ScanoutFrameMatchesUploadedPixelsAndFrameCrc) {
  auto board = emu::open_emulated_board(test::profile_for(GetParam()));
  ASSERT_TRUE(board) << board.error().message;
  auto& b = *board->backend;
  const unsigned w = 16, h = 8;
  const auto pixels = pattern(w * h * 4, 3);
  ASSERT_TRUE(b.upload(0x8000, pixels));
  std::shared_ptr<const backends::ScanoutFrame> got;
  b.set_scanout_callback([&](std::shared_ptr<const backends::ScanoutFrame> f) { got = std::move(f); });
  std::vector<std::uint8_t> bytes;
  protocol::append(bytes, protocol::write_frame(Reg::FB_FORMAT, (std::uint64_t{h} << 16) | w));
  protocol::append(bytes, protocol::write_frame(Reg::FB_DISPLAY, 0x8000));
  ASSERT_TRUE(b.write_frames(protocol::FrameView{bytes}));
  ASSERT_TRUE(got);
  EXPECT_EQ(got->width, w);
  EXPECT_EQ(got->height, h);
  EXPECT_EQ(got->pixels, pixels);
  EXPECT_EQ(got->crc, protocol::crc32(pixels));
}

INSTANTIATE_TEST_SUITE_P(Chips, BoardEndToEnd, ::testing::Values(BridgeChip::FT232H, BridgeChip::FT2232H, BridgeChip::FT4232H,
                                                           BridgeChip::CH341A, BridgeChip::MCP2210, BridgeChip::CP2130),
                         [](const auto& i) { return std::string(to_string(i.param)); });

TEST(BoardBackend, SlowDeviceWithBusyPinNeverOverflows) {
  emu::EmulationOptions eo;
  eo.drain_per_frame = 1;  // the device executes one command per received frame: FIFO fills
  eo.use_simulator = false;
  auto board = emu::open_emulated_board(test::profile_for(BridgeChip::FT232H, /*busy_pin=*/true), eo);
  ASSERT_TRUE(board) << board.error().message;
  std::vector<std::uint8_t> bytes;
  for (int i = 0; i < 2000; ++i) protocol::append(bytes, protocol::write_frame(Reg::FENCE, static_cast<std::uint64_t>(i)));
  ASSERT_TRUE(board->backend->write_frames(protocol::FrameView{bytes}));
  ASSERT_TRUE(board->backend->flush());
  auto status = board->backend->read_register(protocol::index_of(Reg::STATUS));
  ASSERT_TRUE(status);
  EXPECT_EQ(*status >> 48, 0u) << protocol::describe_errors(static_cast<std::uint16_t>(*status >> 48));
  auto fence = board->backend->read_register(protocol::index_of(Reg::FENCE));
  ASSERT_TRUE(fence);
  EXPECT_EQ(*fence, 1999u);
  EXPECT_GT(board->backend->bridge().stats().busy_waits, 0u);
}

TEST(BoardBackend, SlowDeviceWithoutBusyPinUsesFifoCredits) {
  emu::EmulationOptions eo;
  eo.drain_per_frame = 1;
  eo.use_simulator = false;
  auto board = emu::open_emulated_board(test::profile_for(BridgeChip::FT232H, /*busy_pin=*/false), eo);
  ASSERT_TRUE(board) << board.error().message;
  std::vector<std::uint8_t> bytes;
  for (int i = 0; i < 1000; ++i) protocol::append(bytes, protocol::write_frame(Reg::FENCE, static_cast<std::uint64_t>(i)));
  ASSERT_TRUE(board->backend->write_frames(protocol::FrameView{bytes}));
  ASSERT_TRUE(board->backend->flush());
  auto status = board->backend->read_register(protocol::index_of(Reg::STATUS));
  ASSERT_TRUE(status);
  EXPECT_EQ(*status >> 48, 0u) << protocol::describe_errors(static_cast<std::uint16_t>(*status >> 48));
  auto fence = board->backend->read_register(protocol::index_of(Reg::FENCE));
  ASSERT_TRUE(fence);
  EXPECT_EQ(*fence, 999u);
}

TEST(BoardBackend, MosiBitFlipIsCaughtByTheLinkCheckAndResent) {
  emu::EmulationOptions eo;
  eo.use_simulator = false;
  auto board = emu::open_emulated_board(test::profile_for(BridgeChip::FT232H), eo);
  ASSERT_TRUE(board) << board.error().message;
  const auto data = pattern(4096, 11);
  // Flip a bit somewhere inside the upload's MEM_DATA stream.
  board->stack->spi_faults().flip_mosi_bit = board->stack->slave().frames_completed() * 72 + 72 * 40 + 30;
  ASSERT_TRUE(board->backend->upload(0, data));
  EXPECT_GT(board->backend->link_stats().groups_resent, 0u);
  board->stack->spi_faults().flip_mosi_bit.reset();
  auto back = board->backend->readback(0, 4096);
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, data);
}

// A board keeps its state between host sessions, strict link mode included, and a session whose
// profile turns strict mode off would see every write held forever. Attaching without strict mode
// therefore leaves it, with LINK_CTRL.CLEAR_KEY on a 1.3 device (which refuses a plain 0).
TEST(BoardBackend, AttachWithoutStrictModeLeavesWhatAnEarlierSessionSwitchedOn) {
  auto profile = test::profile_for(BridgeChip::FT232H);
  auto earlier = emu::open_emulated_board(profile);
  ASSERT_TRUE(earlier) << earlier.error().message;
  ASSERT_TRUE(earlier->backend->strict_link());
  earlier->backend.reset();  // the session ends; the board stays in strict mode
  profile.strict_link = false;
  auto bridge = open_bridge(profile, earlier->stack->transport());
  ASSERT_TRUE(bridge) << bridge.error().message;
  auto b = BoardBackend::attach(profile, earlier->stack, std::move(*bridge));
  ASSERT_TRUE(b) << b.error().message;
  EXPECT_FALSE((*b)->strict_link());
  std::vector<std::uint8_t> bytes;
  protocol::append(bytes, protocol::write_frame(Reg::CLEAR_COLOR, 0x10203040));
  protocol::append(bytes, protocol::write_frame(Reg::FENCE, 3));
  ASSERT_TRUE((*b)->write_frames(protocol::FrameView{bytes}));
  ASSERT_TRUE((*b)->flush()) << "writes held by strict mode";
  auto reg = [&](Reg r) {
    auto v = (*b)->read_register(protocol::index_of(r));
    EXPECT_TRUE(v) << v.error().message;
    return v ? *v : ~0ull;
  };
  EXPECT_EQ(reg(Reg::LINK_CTRL), 0u);
  EXPECT_EQ(reg(Reg::FENCE), 3u);
  EXPECT_EQ(reg(Reg::STATUS) >> 48, 0u) << "the clear was refused or flagged";
}

TEST(BoardBackend, RejectsReadFramesAndLinkRegistersInWriteBatches) {
  auto board = emu::open_emulated_board(test::profile_for(BridgeChip::FT232H));
  ASSERT_TRUE(board);
  std::vector<std::uint8_t> bytes;
  protocol::append(bytes, protocol::read_frame(Reg::STATUS));
  auto r = board->backend->write_frames(protocol::FrameView{bytes});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, backends::kBadRequest);
  bytes.clear();
  protocol::append(bytes, protocol::write_frame(Reg::LINK_CTRL, 0));
  EXPECT_FALSE(board->backend->write_frames(protocol::FrameView{bytes}));
  EXPECT_FALSE(board->backend->readback(0xFFFFFFF0u, 64)) << "beyond video memory";
  auto none = board->backend->readback(13, 0);
  ASSERT_TRUE(none);
  EXPECT_TRUE(none->empty());
  EXPECT_FALSE(board->backend->upload(3, std::vector<std::uint8_t>(8))) << "MEM_ADDR is 8-byte granular";
}

}  // namespace
}  // namespace gpubridge::usb
