#pragma once
// Silicon Labs CP2130 as an SpiBridge: vendor control requests for SPI word (mode, clock) and chip
// select, then bulk commands with an 8-byte header (00 00 cmd 00 len32LE): Write (0x01) for
// write-only windows, WriteRead (0x02) in ≤ 54-byte pieces (whole frames, one 64-byte packet).
#include <memory>

#include "gpubridge/usb/spi_bridge.hpp"
#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb {

class Cp2130Bridge final : public SpiBridge {
 public:
  static Result<std::unique_ptr<Cp2130Bridge>> open(UsbDevice& dev, unsigned cs_channel, std::uint32_t clock_hz);
  ~Cp2130Bridge() override;
  std::string_view chip() const override { return "CP2130"; }
  Result<std::uint32_t> set_clock(std::uint32_t hz) override;
  std::uint32_t clock_hz() const override { return clock_hz_; }
  bool hardware_busy_wait() const override { return false; }
  std::size_t preferred_batch_bytes() const override { return 4096; }
  Result<std::vector<std::uint8_t>> transfer(std::span<const SpiWindow> windows) override;
  Result<void> recover() override;
  const BridgeStats& stats() const override { return stats_; }

  static constexpr std::size_t kWriteReadChunk = 54;  // 6 frames + 8-byte header fit one packet

 private:
  Cp2130Bridge(UsbDevice& dev, unsigned cs, std::uint32_t hz) : dev_(dev), cs_(cs), clock_hz_(hz) {}
  Result<void> control(std::uint8_t request, std::span<const std::uint8_t> data, const char* what);
  Result<void> out(std::span<const std::uint8_t> bytes);
  Result<void> in(std::span<std::uint8_t> bytes);
  UsbDevice& dev_;
  unsigned cs_;
  std::uint32_t clock_hz_;
  bool claimed_ = false;
  BridgeStats stats_;
};

}  // namespace gpubridge::usb
