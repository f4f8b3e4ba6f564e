// The FTDI MPSSE driver's byte stream, checked against the MPSSE chip model.
#include <gtest/gtest.h>

#include <algorithm>

#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "gpubridge/usb/emu/mpsse_model.hpp"
#include "gpubridge/usb/emu/reference_target.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"
#include "gpubridge/usb/ftdi_mpsse.hpp"
#include "forwarding_usb_device.hpp"
#include "test_profiles.hpp"

namespace gpubridge::usb {
namespace {

using protocol::Reg;

struct FtdiRig {
  emu::ReferenceTarget target{emu::ReferenceTargetConfig{}};
  emu::SpiSlave slave{target, [this] { target.power_cycle(); }, [this] { target.tick(); }};
  emu::MpsseModel model;
  explicit FtdiRig(emu::MpsseModelConfig cfg = {}) : model(cfg, &slave) {}
};

TEST(FtdiDriver, RegisterWriteIsTheDocumented18Bytes) {
  FtdiRig rig;
  auto bridge = FtdiMpsseBridge::open(rig.model, FtdiConfig{});
  ASSERT_TRUE(bridge) << bridge.error().message;
  const auto frame = protocol::encode(protocol::write_frame(Reg::COLOR, 0x1122334455667788ull));
  const SpiWindow w{frame, false, {}};
  rig.model.clear_out_log();
  auto r = (*bridge)->transfer(std::span(&w, 1));
  ASSERT_TRUE(r) << r.error().message;
  // usb-spi-bridges.md 1.6: CS low, 0x11 with length 9-1, the 9 frame bytes, CS high; no 0x87.
  const std::vector<std::uint8_t> expected = {0x80, 0x00, 0x0b, 0x11, 0x08, 0x00, 0x00, 0x11, 0x22, 0x33,
                                              0x44, 0x55, 0x66, 0x77, 0x88, 0x80, 0x08, 0x0b};
  ASSERT_EQ(rig.model.out_log().size(), 1u);
  EXPECT_EQ(rig.model.out_log()[0], expected);
  EXPECT_EQ(rig.target.reg(0x00), 0x1122334455667788ull) << "the frame reached the device register file";
  EXPECT_TRUE(rig.model.violations().empty());
}

TEST(FtdiDriver, InitSequenceEndsInMpsseAndPassesSyncCheck) {
  FtdiRig rig;
  auto bridge = FtdiMpsseBridge::open(rig.model, FtdiConfig{});
  ASSERT_TRUE(bridge) << bridge.error().message;
  EXPECT_TRUE(rig.model.violations().empty()) << rig.model.violations()[0];
  EXPECT_EQ(rig.model.sck_hz(), 30'000'000u);
  EXPECT_EQ((*bridge)->clock_hz(), 30'000'000u);
  auto c = (*bridge)->set_clock(7'000'000);
  ASSERT_TRUE(c);
  EXPECT_LE(*c, 7'000'000u);
  EXPECT_EQ(*c, rig.model.sck_hz());
}

TEST(FtdiDriver, ReadFrameReturnsStatusByteAndValue) {
  FtdiRig rig;
  auto bridge = FtdiMpsseBridge::open(rig.model, FtdiConfig{});
  ASSERT_TRUE(bridge);
  const auto frame = protocol::encode(protocol::read_frame(Reg::ID));
  const SpiWindow w{frame, true, {}};
  auto r = (*bridge)->transfer(std::span(&w, 1));
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->size(), 9u);
  EXPECT_TRUE(protocol::miso_status_valid((*r)[0]));
  std::uint64_t id = 0;
  for (int i = 1; i < 9; ++i) id = id << 8 | (*r)[i];
  EXPECT_EQ(id >> 32, protocol::kIdMagic);
}

TEST(FtdiDriver, BusyWaitOpcodePrecedesEachGroupWhenThePinIsWired) {
  emu::MpsseModelConfig mc;
  mc.busy_wired = true;
  FtdiRig rig(mc);
  FtdiConfig fc;
  fc.busy_pin = true;
  auto bridge = FtdiMpsseBridge::open(rig.model, fc);
  ASSERT_TRUE(bridge);
  std::vector<std::uint8_t> mosi;
  for (int i = 0; i < 4; ++i) protocol::append(mosi, protocol::write_frame(Reg::COLOR, static_cast<std::uint64_t>(i)));
  SpiWindow w{mosi, false, {0, 18}};
  const auto cmd = (*bridge)->encode(std::span(&w, 1));
  // CS low, 0x89, 2 frames, 0x89, 2 frames, CS high.
  ASSERT_GE(cmd.size(), 3u + 1 + 3 + 18 + 1 + 3 + 18 + 3);
  EXPECT_EQ(cmd[3], 0x89);
  EXPECT_EQ(cmd[4], 0x11);
  EXPECT_EQ(cmd[5], 17);
  EXPECT_EQ(cmd[3 + 1 + 3 + 18], 0x89);
  fc.busy_pin = false;
  FtdiRig rig2;
  auto plain = FtdiMpsseBridge::open(rig2.model, fc);
  ASSERT_TRUE(plain);
  const auto cmd2 = (*plain)->encode(std::span(&w, 1));
  EXPECT_EQ(std::count(cmd2.begin(), cmd2.end(), 0x89), std::count(mosi.begin(), mosi.end(), 0x89))
      << "no wait-on-I/O opcodes when BUSY is not wired";
}

TEST(FtdiDriver, LargeReadsAreStrippedAtEveryPacketBoundaryAtFullSpeed) {
  for (bool hs : {true, false}) {
    emu::MpsseModelConfig mc;
    mc.high_speed = hs;
    FtdiRig rig(mc);
    auto bridge = FtdiMpsseBridge::open(rig.model, FtdiConfig{});
    ASSERT_TRUE(bridge);
    // 300 ID reads = 2700 bytes: crosses 62- and 510-byte payload boundaries and the RX FIFO size.
    std::vector<std::uint8_t> mosi;
    for (int i = 0; i < 300; ++i) protocol::append(mosi, protocol::read_frame(Reg::ID));
    const SpiWindow w{mosi, true, {}};
    auto r = (*bridge)->transfer(std::span(&w, 1));
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->size(), mosi.size());
    for (int i = 0; i < 300; ++i) {
      std::uint64_t id = 0;
      for (int b = 1; b < 9; ++b) id = id << 8 | (*r)[static_cast<std::size_t>(i * 9 + b)];
      ASSERT_EQ(id >> 32, protocol::kIdMagic) << "frame " << i << (hs ? " high speed" : " full speed");
      ASSERT_TRUE(protocol::miso_status_valid((*r)[static_cast<std::size_t>(i * 9)]));
    }
    EXPECT_TRUE(rig.model.violations().empty());
  }
}

// 300 ID reads (2,700 MISO bytes, more than the FT232H's 1 KiB RX FIFO) through one bridge.
std::vector<std::uint8_t> many_id_reads() {
  std::vector<std::uint8_t> mosi;
  for (int i = 0; i < 300; ++i) protocol::append(mosi, protocol::read_frame(Reg::ID));
  return mosi;
}

TEST(FtdiDriver, ReadsBeyondTheRxFifoStreamInOneRoundTripWithTheSameBytes) {
  std::vector<std::uint8_t> results[2];
  for (bool stream : {true, false}) {
    FtdiRig rig;
    FtdiConfig cfg;
    cfg.stream_reads = stream;
    auto bridge = FtdiMpsseBridge::open(rig.model, cfg);
    ASSERT_TRUE(bridge) << bridge.error().message;
    const auto mosi = many_id_reads();
    const SpiWindow w{mosi, true, {}};
    const BridgeStats before = (*bridge)->stats();
    auto r = (*bridge)->transfer(std::span(&w, 1));
    ASSERT_TRUE(r) << r.error().message;
    const BridgeStats& after = (*bridge)->stats();
    if (stream) {
      EXPECT_EQ(after.streamed_reads - before.streamed_reads, 1u);
      EXPECT_EQ(after.round_trips - before.round_trips, 1u) << "one wait for the device, however much is read";
    } else {
      EXPECT_EQ(after.streamed_reads, before.streamed_reads);
      EXPECT_GE(after.round_trips - before.round_trips, 3u) << "2,700 bytes need at least three 1 KiB rounds";
    }
    EXPECT_TRUE(rig.model.violations().empty()) << rig.model.violations()[0];
    results[stream ? 0 : 1] = std::move(*r);
  }
  ASSERT_EQ(results[0].size(), 2700u);
  EXPECT_EQ(results[0], results[1]) << "streamed and synchronous reads must clock out the same MISO bytes";
}

// A UsbDevice without an asynchronous path (the base class's bulk_stream): the driver must fall
// back to synchronous rounds, once, and still read correctly.
class NoStreamDevice final : public testing::ForwardingUsbDevice {
  using ForwardingUsbDevice::ForwardingUsbDevice;  // everything but bulk_stream, which says NotSupported
};

TEST(FtdiDriver, DevicesWithoutAnAsynchronousPathFallBackToRounds) {
  FtdiRig rig;
  NoStreamDevice dev(rig.model);
  auto bridge = FtdiMpsseBridge::open(dev, FtdiConfig{});
  ASSERT_TRUE(bridge) << bridge.error().message;
  const auto mosi = many_id_reads();
  const SpiWindow w{mosi, true, {}};
  for (int pass = 0; pass < 2; ++pass) {
    auto r = (*bridge)->transfer(std::span(&w, 1));
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->size(), mosi.size());
    EXPECT_EQ((*r)[1], 0x53) << "ID magic 'S' in the first frame";
  }
  EXPECT_EQ((*bridge)->stats().streamed_reads, 0u);
  EXPECT_TRUE(rig.model.violations().empty()) << rig.model.violations()[0];
}

TEST(FtdiDriver, AFaultInsideAStreamIsSpecificAndTheBridgeRecovers) {
  // Find the operation indices a streamed read spans, then fail each of them once.
  std::uint64_t first_op = 0, end_op = 0;
  {
    FtdiRig rig;
    auto bridge = FtdiMpsseBridge::open(rig.model, FtdiConfig{});
    ASSERT_TRUE(bridge);
    const auto mosi = many_id_reads();
    const SpiWindow w{mosi, true, {}};
    first_op = rig.model.faults().ops;
    ASSERT_TRUE((*bridge)->transfer(std::span(&w, 1)));
    end_op = rig.model.faults().ops;
  }
  ASSERT_GT(end_op - first_op, 3u) << "several OUT and IN transfers make up the stream";
  for (auto fault : {emu::UsbFault::TimeoutPartial, emu::UsbFault::Stall}) {
    for (std::uint64_t op = first_op; op < end_op; ++op) {
      SCOPED_TRACE("fault " + std::to_string(static_cast<int>(fault)) + " at op " + std::to_string(op));
      FtdiRig rig;
      rig.model.faults().at_op = op;
      rig.model.faults().fault = fault;
      rig.model.faults().partial_bytes = 100;
      auto bridge = FtdiMpsseBridge::open(rig.model, FtdiConfig{});
      ASSERT_TRUE(bridge);
      const auto mosi = many_id_reads();
      const SpiWindow w{mosi, true, {}};
      auto bad = (*bridge)->transfer(std::span(&w, 1));
      ASSERT_FALSE(bad) << "a lost transfer cannot give a complete read";
      EXPECT_TRUE(bad.error().code == backends::kDeviceTimeout || bad.error().code == backends::kDeviceProtocol) << bad.error().message;
      EXPECT_NE(bad.error().message.find("streamed read"), std::string::npos) << bad.error().message;
      ASSERT_TRUE((*bridge)->recover()) << "purge + sync check bring the stream back in step";
      auto good = (*bridge)->transfer(std::span(&w, 1));
      ASSERT_TRUE(good) << good.error().message;
      EXPECT_EQ((*good)[1], 0x53);
      EXPECT_EQ((*good)[299 * 9 + 1], 0x53);
    }
  }
}

TEST(FtdiDriver, RejectsWiringTheChipCannotDo) {
  FtdiRig rig;
  FtdiConfig fc;
  fc.channel = 1;  // FT232H has only channel A
  auto b = FtdiMpsseBridge::open(rig.model, fc);
  ASSERT_FALSE(b);
  EXPECT_NE(b.error().message.find("channel"), std::string::npos);
  fc.channel = 0;
  fc.cs_pin = 1;  // DO
  EXPECT_FALSE(FtdiMpsseBridge::open(rig.model, fc));
}

TEST(FtdiDriver, BusyInterfaceAndUnplugGiveActionableErrors) {
  FtdiRig rig;
  rig.model.faults().at_op = 0;
  rig.model.faults().fault = emu::UsbFault::NoDevice;
  auto b = FtdiMpsseBridge::open(rig.model, FtdiConfig{});
  ASSERT_FALSE(b);
  EXPECT_EQ(b.error().code, backends::kDeviceGone);
  EXPECT_NE(b.error().message.find("unplugged"), std::string::npos);
}

}  // namespace
}  // namespace gpubridge::usb
