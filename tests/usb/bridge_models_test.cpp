// CH341A, MCP2210 and CP2130 models: exact driver byte streams and what the chips reject.
#include <gtest/gtest.h>

#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/usb/ch341a.hpp"
#include "gpubridge/usb/cp2130.hpp"
#include "gpubridge/usb/emu/ch341a_model.hpp"
#include "gpubridge/usb/emu/cp2130_model.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "gpubridge/usb/emu/mcp2210_model.hpp"
#include "gpubridge/usb/emu/reference_target.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"
#include "gpubridge/usb/mcp2210.hpp"
#include "test_profiles.hpp"

namespace gpubridge::usb {
namespace {

using protocol::Reg;

struct Slave {
  emu::ReferenceTarget target{emu::ReferenceTargetConfig{}};
  emu::SpiSlave slave{target, nullptr, nullptr};
};

TEST(Ch341a, ReversesBitsAndDrivesCsThroughUio) {
  Slave s;
  emu::Ch341aModel model(&s.slave, "X");
  auto b = Ch341aBridge::open(model);
  ASSERT_TRUE(b) << b.error().message;
  const auto frame = protocol::encode(protocol::read_frame(Reg::ID));
  const SpiWindow w{frame, true, {}};
  auto r = (*b)->transfer(std::span(&w, 1));
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->size(), 9u);
  EXPECT_EQ((*r)[1], 0x53) << "MISO bytes are reversed back to MSB-first";
  EXPECT_EQ(s.slave.frames_completed(), 1u);
  EXPECT_EQ(s.slave.frames_aborted(), 0u);
  EXPECT_TRUE(model.violations().empty()) << model.violations()[0];
  EXPECT_EQ(reverse_bits(0x01), 0x80);
  EXPECT_EQ(reverse_bits(0xA0), 0x05);
}

TEST(Ch341a, ModelFlagsSpiBeforePinsAreEnabled) {
  Slave s;
  emu::Ch341aModel model(&s.slave, "X");
  ASSERT_EQ(model.claim_interface(0), UsbStatus::Ok);
  const std::uint8_t data[] = {0xA8, 0x01, 0x02};
  ASSERT_TRUE(model.bulk_out(0x02, data, 100).ok());
  ASSERT_FALSE(model.violations().empty());
}

TEST(Mcp2210, RetriesBusyAndReportsExternalMaster) {
  Slave s;
  emu::Mcp2210Model model(&s.slave, "X");
  auto b = Mcp2210Bridge::open(model, 0, 12'000'000);
  ASSERT_TRUE(b) << b.error().message;
  std::vector<std::uint8_t> mosi;
  for (int i = 0; i < 10; ++i) protocol::append(mosi, protocol::read_frame(Reg::ID));  // 90 bytes: two reports
  const SpiWindow w{mosi, true, {}};
  model.inject_busy = 3;
  auto r = (*b)->transfer(std::span(&w, 1));
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->size(), 90u);
  for (int i = 0; i < 10; ++i) EXPECT_EQ((*r)[static_cast<std::size_t>(i * 9 + 1)], 0x53);
  EXPECT_EQ(s.slave.frames_completed(), 10u);
  model.inject_busy = Mcp2210Bridge::kBusyRetries + 5;
  auto busy = (*b)->transfer(std::span(&w, 1));
  ASSERT_FALSE(busy);
  EXPECT_EQ(busy.error().code, backends::kDeviceTimeout);
  model.inject_busy = 0;
  model.external_master = true;
  auto ext = (*b)->transfer(std::span(&w, 1));
  ASSERT_FALSE(ext);
  EXPECT_NE(ext.error().message.find("external master"), std::string::npos);
  EXPECT_TRUE(model.violations().empty()) << model.violations()[0];
}

TEST(Mcp2210, ModelRejectsReportsWithoutReportId) {
  emu::Mcp2210Model model(nullptr, "X");
  std::vector<std::uint8_t> r(64, 0);
  r[0] = 0x10;
  EXPECT_EQ(model.write(r), -1);
  EXPECT_FALSE(model.violations().empty());
}

TEST(Cp2130, WriteIsOneHeaderedBulkCommand) {
  Slave s;
  emu::Cp2130Model model(&s.slave, "X");
  auto b = Cp2130Bridge::open(model, 0, 12'000'000);
  ASSERT_TRUE(b) << b.error().message;
  EXPECT_EQ((*b)->clock_hz(), 12'000'000u);
  const auto frame = protocol::encode(protocol::write_frame(Reg::HOST_TAG, 0x55));
  const SpiWindow w{frame, false, {}};
  ASSERT_TRUE((*b)->transfer(std::span(&w, 1)));
  EXPECT_EQ(s.target.read_register(protocol::index_of(Reg::HOST_TAG)), 0x55u);
  EXPECT_TRUE(model.violations().empty());
  // One-time-programmable requests are refused by the model.
  EXPECT_EQ(model.control_out(0x40, 0x61, 0, 0, std::vector<std::uint8_t>(2), 100).status, UsbStatus::Pipe);
  EXPECT_FALSE(model.violations().empty());
}

TEST(Cp2130, ClockRoundsDownToTheChipsSteps) {
  Slave s;
  emu::Cp2130Model model(&s.slave, "X");
  auto b = Cp2130Bridge::open(model, 0, 5'000'000);
  ASSERT_TRUE(b);
  EXPECT_EQ((*b)->clock_hz(), 3'000'000u);
}

}  // namespace
}  // namespace gpubridge::usb
