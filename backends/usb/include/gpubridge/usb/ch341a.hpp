#pragma once
// WCH CH341A as an SpiBridge: 32-byte packets, A8 SPI stream with 31 data bytes per packet
// (LSB first on the wire, so every byte is bit-reversed), chip select through the AB UIO stream.
#include <memory>

#include "gpubridge/usb/spi_bridge.hpp"
#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb {

inline constexpr std::size_t kCh341Packet = 32;
std::uint8_t reverse_bits(std::uint8_t b);

class Ch341aBridge final : public SpiBridge {
 public:
  static Result<std::unique_ptr<Ch341aBridge>> open(UsbDevice& dev, unsigned timeout_ms = 1000);
  ~Ch341aBridge() override;
  std::string_view chip() const override { return "CH341A"; }
  Result<std::uint32_t> set_clock(std::uint32_t) override { return clock_hz(); }  // fixed in hardware
  std::uint32_t clock_hz() const override { return 1'500'000; }
  bool hardware_busy_wait() const override { return false; }
  std::size_t preferred_batch_bytes() const override { return 2048; }
  Result<std::vector<std::uint8_t>> transfer(std::span<const SpiWindow> windows) override;
  Result<void> recover() override;
  const BridgeStats& stats() const override { return stats_; }

 private:
  Ch341aBridge(UsbDevice& dev, unsigned timeout_ms) : dev_(dev), timeout_ms_(timeout_ms) {}
  Result<void> out(std::span<const std::uint8_t> bytes);
  Result<void> in(std::span<std::uint8_t> bytes);
  UsbDevice& dev_;
  unsigned timeout_ms_;
  bool claimed_ = false;
  BridgeStats stats_;
};

}  // namespace gpubridge::usb
