// The MPSSE chip model rejects what a real FT232H/FT2232H/FT4232H would reject.
#include <gtest/gtest.h>

#include "gpubridge/usb/emu/mpsse_model.hpp"
#include "gpubridge/usb/emu/reference_target.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"

namespace gpubridge::usb::emu {
namespace {

struct Rig {
  ReferenceTarget target{ReferenceTargetConfig{}};
  SpiSlave slave{target, nullptr, [this] { target.tick(); }};
  MpsseModel model;
  explicit Rig(MpsseModelConfig cfg = {}) : model(cfg, &slave) {}
  void enter_mpsse() {
    ASSERT_EQ(model.detach_kernel_driver(0), UsbStatus::Ok);
    ASSERT_EQ(model.claim_interface(0), UsbStatus::Ok);
    ASSERT_TRUE(model.control_out(0x40, 0x0B, 0x020B, 1, {}, 100).ok());
  }
  std::vector<std::uint8_t> read_all() {
    std::vector<std::uint8_t> buf(512);
    auto io = model.bulk_in(0x81, buf, 100);
    EXPECT_TRUE(io.ok());
    buf.resize(io.transferred);
    return buf;
  }
};

TEST(MpsseModel, ClaimFailsWhileTheKernelDriverIsBound) {
  Rig rig;
  EXPECT_EQ(rig.model.claim_interface(0), UsbStatus::Busy);
  EXPECT_EQ(rig.model.detach_kernel_driver(0), UsbStatus::Ok);
  EXPECT_EQ(rig.model.detach_kernel_driver(0), UsbStatus::NotFound) << "nothing left to detach";
  EXPECT_EQ(rig.model.claim_interface(0), UsbStatus::Ok);
  EXPECT_EQ(rig.model.claim_interface(1), UsbStatus::NotFound) << "FT232H has one interface";
}

TEST(MpsseModel, BadOpcodeIsAnsweredWithFA) {
  Rig rig;
  rig.enter_mpsse();
  const std::uint8_t cmd[] = {0xAB, 0x87};
  ASSERT_TRUE(rig.model.bulk_out(0x02, cmd, 100).ok());
  const auto in = rig.read_all();
  ASSERT_EQ(in.size(), 4u);
  EXPECT_EQ(in[0], 0x32);
  EXPECT_EQ(in[1], 0x60);
  EXPECT_EQ(in[2], 0xFA);
  EXPECT_EQ(in[3], 0xAB);
}

TEST(MpsseModel, Ft4232hHasNoHighByte) {
  MpsseModelConfig c;
  c.chip = FtdiChip::FT4232H;
  Rig rig(c);
  rig.enter_mpsse();
  const std::uint8_t cmd[] = {0x82, 0x00, 0x00};
  ASSERT_TRUE(rig.model.bulk_out(0x02, cmd, 100).ok());
  const auto in = rig.read_all();
  ASSERT_GE(in.size(), 4u);
  EXPECT_EQ(in[2], 0xFA);
  EXPECT_EQ(in[3], 0x82);
}

TEST(MpsseModel, StatusOnlyPacketWhenNothingIsPending) {
  Rig rig;
  rig.enter_mpsse();
  const auto in = rig.read_all();
  EXPECT_EQ(in, (std::vector<std::uint8_t>{0x32, 0x60}));
}

TEST(MpsseModel, RejectsUnknownRequestsWrongChannelsAndUnclaimedBulk) {
  Rig rig;
  EXPECT_EQ(rig.model.bulk_out(0x02, std::vector<std::uint8_t>{0x87}, 100).status, UsbStatus::Io) << "not claimed";
  EXPECT_EQ(rig.model.control_out(0x40, 0x0B, 0x0200, 2, {}, 100).status, UsbStatus::Pipe) << "FT232H has no channel B";
  EXPECT_EQ(rig.model.control_out(0x40, 0x55, 0, 1, {}, 100).status, UsbStatus::Pipe);
  EXPECT_EQ(rig.model.control_out(0x40, 0x0B, 0x0700, 1, {}, 100).status, UsbStatus::Pipe) << "bitmode 7 is not MPSSE";
  EXPECT_EQ(rig.model.violations().size(), 4u);
}

TEST(MpsseModel, RisingEdgeWritesAreFlaggedForSpiMode0) {
  Rig rig;
  rig.enter_mpsse();
  const std::uint8_t cmd[] = {0x80, 0x08, 0x0b, 0x10, 0x00, 0x00, 0x55};
  ASSERT_TRUE(rig.model.bulk_out(0x02, cmd, 100).ok());
  ASSERT_EQ(rig.model.violations().size(), 1u);
  EXPECT_NE(rig.model.violations()[0].find("rising edge"), std::string::npos);
}

TEST(MpsseModel, CommandsMaySpanBulkTransfers) {
  Rig rig;
  rig.enter_mpsse();
  // A 9-byte full-duplex read of ID split across three OUT transfers.
  const std::uint8_t a[] = {0x80, 0x00, 0x0b, 0x31, 0x08};
  const std::uint8_t b[] = {0x00, 0xFF, 0, 0, 0};
  const std::uint8_t c[] = {0, 0, 0, 0, 0, 0x80, 0x08, 0x0b, 0x87};
  ASSERT_TRUE(rig.model.bulk_out(0x02, a, 100).ok());
  ASSERT_TRUE(rig.model.bulk_out(0x02, b, 100).ok());
  ASSERT_TRUE(rig.model.bulk_out(0x02, c, 100).ok());
  const auto in = rig.read_all();
  ASSERT_EQ(in.size(), 2u + 9u);
  EXPECT_EQ(in[2] & 0xC0, 0x80) << "status marker";
  EXPECT_EQ(in[3], 0x53);  // 'S' of the ID magic
  EXPECT_EQ(rig.slave.frames_completed(), 1u);
}

TEST(MpsseModel, InBufferSmallerThanAPacketOverflows) {
  Rig rig;
  rig.enter_mpsse();
  std::vector<std::uint8_t> cmd = {0x80, 0x00, 0x0b, 0x31, 0x63, 0x00};  // 100 bytes full duplex
  cmd.resize(cmd.size() + 100, 0xFF);
  cmd.push_back(0x87);
  ASSERT_TRUE(rig.model.bulk_out(0x02, cmd, 100).ok());
  std::vector<std::uint8_t> small(64);
  EXPECT_EQ(rig.model.bulk_in(0x81, small, 100).status, UsbStatus::Overflow);
}

TEST(MpsseModel, WaitOnBusyStallsUntilTheHostTimesOut) {
  MpsseModelConfig c;
  c.busy_wired = true;
  c.max_wait_ticks = 10;
  Rig rig(c);
  rig.slave.faults().busy_stuck = true;
  rig.enter_mpsse();
  std::vector<std::uint8_t> cmd = {0x80, 0x00, 0x0b, 0x89};
  cmd.resize(5000, 0x87);  // more than the 1 KiB TX FIFO behind a stalled MPSSE
  const auto io = rig.model.bulk_out(0x02, cmd, 100);
  EXPECT_EQ(io.status, UsbStatus::Timeout);
  EXPECT_LT(io.transferred, cmd.size());
}

}  // namespace
}  // namespace gpubridge::usb::emu
