// Transport errors become messages that say what to fix, with the right BackendError code; and
// FTDI variants (falling read edge, full-speed packets) work end to end.
#include <gtest/gtest.h>

#include <random>

#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "gpubridge/usb/usb_errors.hpp"
#include "test_profiles.hpp"

namespace gpubridge::usb {
namespace {

TEST(UsbErrors, MessagesSayWhatToFix) {
  const auto access = usb_error(UsbStatus::Access, "FT232H 0403:6014 (port 1-2): open");
  EXPECT_NE(access.message.find("configs/udev/70-gpubridge.rules"), std::string::npos);
  EXPECT_NE(access.message.find("udevadm control --reload"), std::string::npos);
  EXPECT_NE(access.message.find("port 1-2"), std::string::npos);
  const auto busy = usb_error(UsbStatus::Busy, "claim");
  EXPECT_NE(busy.message.find("ftdi_sio"), std::string::npos);
  const auto gone = usb_error(UsbStatus::NoDevice, "bulk OUT");
  EXPECT_NE(gone.message.find("unplugged"), std::string::npos);
  EXPECT_EQ(gone.code, backends::kDeviceGone);
  EXPECT_EQ(usb_error(UsbStatus::Io, "x").code, backends::kDeviceGone);
  EXPECT_EQ(usb_error(UsbStatus::Timeout, "x").code, backends::kDeviceTimeout);
  EXPECT_EQ(usb_error(UsbStatus::Pipe, "x").code, backends::kDeviceProtocol);
}

void round_trip(const BoardProfile& p, emu::EmulationOptions eo) {
  auto board = emu::open_emulated_board(p, eo);
  ASSERT_TRUE(board) << board.error().message;
  std::vector<std::uint8_t> data(3000);
  std::mt19937 rng(9);
  for (auto& b : data) b = static_cast<std::uint8_t>(rng());
  ASSERT_TRUE(board->backend->upload(0x100, data));
  auto back = board->backend->readback(0x100, 3000);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(*back, data);
  const auto v = board->stack->violations();
  EXPECT_TRUE(v.empty()) << v.front();
}

TEST(FtdiVariants, FallingReadEdgeAndFullSpeedPackets) {
  auto p = test::profile_for(BridgeChip::FT2232H);
  p.read_edge = ReadEdge::Falling;
  p.interface = 0;
  round_trip(p, {});
  emu::EmulationOptions fs;
  fs.high_speed = false;  // 64-byte packets: 62 payload bytes each
  round_trip(test::profile_for(BridgeChip::FT232H, /*busy_pin=*/true), fs);
  auto ice = test::profile_for(BridgeChip::FT2232H);
  ice.cs_pin = 4;  // iceprog wiring
  round_trip(ice, {});
}

}  // namespace
}  // namespace gpubridge::usb
