#pragma once
// MCP2210 model behind the HidDevice seam: 65-byte writes with report id 0, one 64-byte response
// per command; 0x10 status, 0x20/0x21 chip settings, 0x40/0x41 SPI transfer settings, 0x42
// transfer state machine (engine status 0x20 started / 0x30 more data / 0x10 done, data returned
// one report late), CS held across reports until the transaction length is reached, injectable
// 0xF8 busy and 0xF7 external-master responses.
#include <array>
#include <deque>
#include <string>
#include <vector>

#include "gpubridge/usb/emu/chip_model.hpp"

namespace gpubridge::usb::emu {

class Mcp2210Model final : public ChipModel, public HidDevice {
 public:
  Mcp2210Model(SpiPins* pins, std::string serial);
  HidDevice* hid() override { return this; }
  const HidDeviceInfo& info() const override { return info_; }
  int write(std::span<const std::uint8_t> data) override;
  int read(std::span<std::uint8_t> data, int timeout_ms) override;
  std::string last_error() const override { return last_error_; }

  unsigned inject_busy = 0;        // the next N transfer commands answer 0xF8
  bool external_master = false;    // transfer commands answer 0xF7

 private:
  std::array<std::uint8_t, 64> handle(std::span<const std::uint8_t, 64> r);
  HidDeviceInfo info_;
  std::string last_error_;
  std::deque<std::array<std::uint8_t, 64>> responses_;
  std::array<std::uint8_t, 64> chip_settings_{}, spi_settings_{};
  bool in_transaction_ = false;
  std::size_t remaining_ = 0;
  std::deque<std::uint8_t> rx_;
};

}  // namespace gpubridge::usb::emu
