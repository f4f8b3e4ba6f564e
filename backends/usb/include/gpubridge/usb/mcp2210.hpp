#pragma once
// Microchip MCP2210 (USB HID) as an SpiBridge: 65-byte writes (report id 0 + 64-byte report),
// 0x21 chip settings (GPn as chip select), 0x40 transfer settings per transaction length, 0x42
// transfers of ≤ 60 bytes with engine status 0x20/0x30/0x10, bounded retries on 0xF8 busy.
#include <array>
#include <memory>

#include "gpubridge/usb/hid_device.hpp"
#include "gpubridge/usb/spi_bridge.hpp"

namespace gpubridge::usb {

class Mcp2210Bridge final : public SpiBridge {
 public:
  static Result<std::unique_ptr<Mcp2210Bridge>> open(HidDevice& dev, unsigned cs_pin, std::uint32_t clock_hz);
  std::string_view chip() const override { return "MCP2210"; }
  Result<std::uint32_t> set_clock(std::uint32_t hz) override;
  std::uint32_t clock_hz() const override { return clock_hz_; }
  bool hardware_busy_wait() const override { return false; }
  std::size_t preferred_batch_bytes() const override { return 1024; }
  Result<std::vector<std::uint8_t>> transfer(std::span<const SpiWindow> windows) override;
  Result<void> recover() override;
  const BridgeStats& stats() const override { return stats_; }

  static constexpr unsigned kBusyRetries = 100;

 private:
  Mcp2210Bridge(HidDevice& dev, unsigned cs_pin, std::uint32_t hz) : dev_(dev), cs_pin_(cs_pin), clock_hz_(hz) {}
  Result<std::array<std::uint8_t, 64>> command(std::span<const std::uint8_t> report);
  Result<void> set_transfer_settings(std::size_t length);
  Result<void> window(std::span<const std::uint8_t> mosi, std::vector<std::uint8_t>* miso);
  HidDevice& dev_;
  unsigned cs_pin_;
  std::uint32_t clock_hz_;
  std::size_t configured_length_ = 0;
  BridgeStats stats_;
};

}  // namespace gpubridge::usb
