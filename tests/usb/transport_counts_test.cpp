// Transports that report more bytes than the buffer they were given: every driver must refuse the
// count as a protocol fault instead of trusting it (fuzz_usb_bridges found the FTDI driver reading
// past its buffer and the CH341A/MCP2210 drivers accepting the count as data), and recover.
#include <gtest/gtest.h>

#include <functional>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/usb/ch341a.hpp"
#include "gpubridge/usb/emu/ch341a_model.hpp"
#include "gpubridge/usb/emu/mcp2210_model.hpp"
#include "gpubridge/usb/emu/mpsse_model.hpp"
#include "gpubridge/usb/emu/reference_target.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"
#include "gpubridge/usb/ftdi_mpsse.hpp"
#include "gpubridge/usb/mcp2210.hpp"
#include "forwarding_usb_device.hpp"

namespace gpubridge::usb {
namespace {

using protocol::Reg;

constexpr std::size_t kExtra = 6;

// A chip model behind a transport that, once armed, reports kExtra bytes more than the buffer of
// the next successful IN transfer (the bytes themselves are the model's).
class OverReportingUsb final : public testing::ForwardingUsbDevice {
 public:
  using ForwardingUsbDevice::ForwardingUsbDevice;
  void arm() { armed_ = true; }
  UsbIo bulk_in(std::uint8_t ep, std::span<std::uint8_t> d, unsigned t) override {
    UsbIo io = ForwardingUsbDevice::bulk_in(ep, d, t);
    if (armed_ && io.ok()) {
      armed_ = false;
      io.transferred = d.size() + kExtra;
    }
    return io;
  }

 private:
  bool armed_ = false;
};

class OverReportingHid final : public HidDevice {
 public:
  explicit OverReportingHid(HidDevice& inner) : in_(inner) {}
  void arm() { armed_ = true; }
  const HidDeviceInfo& info() const override { return in_.info(); }
  int write(std::span<const std::uint8_t> d) override { return in_.write(d); }
  int read(std::span<std::uint8_t> d, int timeout_ms) override {
    const int r = in_.read(d, timeout_ms);
    if (!armed_ || r <= 0) return r;
    armed_ = false;
    return static_cast<int>(d.size() + kExtra);
  }
  std::string last_error() const override { return in_.last_error(); }

 private:
  HidDevice& in_;
  bool armed_ = false;
};

struct Slave {
  emu::ReferenceTarget target{emu::ReferenceTargetConfig{}};
  emu::SpiSlave slave{target, nullptr, nullptr};
};

// Reads the ID register: an over-reported reply must fail as a protocol fault naming the count,
// and after recover() the same read returns the ID magic.
void expect_refused_then_recovered(SpiBridge& bridge, const std::function<void()>& arm) {
  const auto frame = protocol::encode(protocol::read_frame(Reg::ID));
  const SpiWindow w{frame, true, {}};
  arm();
  auto bad = bridge.transfer(std::span(&w, 1));
  ASSERT_FALSE(bad) << "a reply count larger than the buffer was accepted as data";
  EXPECT_EQ(bad.error().code, backends::kDeviceProtocol);
  EXPECT_NE(bad.error().message.find("reported"), std::string::npos) << bad.error().message;
  ASSERT_TRUE(bridge.recover());
  auto good = bridge.transfer(std::span(&w, 1));
  ASSERT_TRUE(good) << good.error().message;
  ASSERT_EQ(good->size(), frame.size());
  EXPECT_EQ((*good)[1], 0x53) << "ID magic 'S'";
}

TEST(TransportCounts, FtdiRefusesAnInCountBeyondItsBuffer) {
  Slave s;
  emu::MpsseModel model(emu::MpsseModelConfig{}, &s.slave);
  OverReportingUsb dev(model);
  auto bridge = FtdiMpsseBridge::open(dev, FtdiConfig{});
  ASSERT_TRUE(bridge) << bridge.error().message;
  expect_refused_then_recovered(**bridge, [&] { dev.arm(); });
}

TEST(TransportCounts, FtdiOpenRefusesAnOverReportedDrain) {
  Slave s;
  emu::MpsseModel model(emu::MpsseModelConfig{}, &s.slave);
  OverReportingUsb dev(model);
  dev.arm();  // the first IN transfer of open() drains stale bytes
  auto bridge = FtdiMpsseBridge::open(dev, FtdiConfig{});
  ASSERT_FALSE(bridge);
  EXPECT_EQ(bridge.error().code, backends::kDeviceProtocol);
  EXPECT_NE(bridge.error().message.find("reported"), std::string::npos) << bridge.error().message;
}

TEST(TransportCounts, Ch341aRefusesAnInCountBeyondItsBuffer) {
  Slave s;
  emu::Ch341aModel model(&s.slave, "X");
  OverReportingUsb dev(model);
  auto bridge = Ch341aBridge::open(dev);
  ASSERT_TRUE(bridge) << bridge.error().message;
  expect_refused_then_recovered(**bridge, [&] { dev.arm(); });
}

TEST(TransportCounts, Mcp2210RefusesAReportLongerThanItsBuffer) {
  Slave s;
  emu::Mcp2210Model model(&s.slave, "X");
  OverReportingHid dev(model);
  auto bridge = Mcp2210Bridge::open(dev, 0, 1'000'000);
  ASSERT_TRUE(bridge) << bridge.error().message;
  expect_refused_then_recovered(**bridge, [&] { dev.arm(); });
}

}  // namespace
}  // namespace gpubridge::usb
