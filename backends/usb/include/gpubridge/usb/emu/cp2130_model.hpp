#pragma once
// CP2130 model behind the UsbDevice seam: vendor requests 0x25 (chip select) and 0x31 (SPI word),
// bulk commands with the 8-byte header on OUT 0x01, read data on IN 0x82 (64-byte packets). Each
// bulk command asserts the selected CS for its whole length.
#include <deque>
#include <string>
#include <vector>

#include "gpubridge/usb/emu/chip_model.hpp"

namespace gpubridge::usb::emu {

class Cp2130Model final : public UsbChipModel {
 public:
  Cp2130Model(SpiPins* pins, std::string serial);
  const UsbDeviceInfo& info() const override { return info_; }
  UsbIo control_out(std::uint8_t request_type, std::uint8_t request, std::uint16_t value, std::uint16_t index,
                    std::span<const std::uint8_t> data, unsigned timeout_ms) override;
  UsbIo control_in(std::uint8_t request_type, std::uint8_t request, std::uint16_t value, std::uint16_t index,
                   std::span<std::uint8_t> data, unsigned timeout_ms) override;
  UsbIo bulk_out(std::uint8_t endpoint, std::span<const std::uint8_t> data, unsigned timeout_ms) override;
  UsbIo bulk_in(std::uint8_t endpoint, std::span<std::uint8_t> data, unsigned timeout_ms) override;
  std::uint16_t max_packet_size(std::uint8_t endpoint) const override;

 private:
  UsbDeviceInfo info_;
  int cs_channel_ = -1;
  std::uint8_t spi_word_[11] = {};
  std::deque<std::uint8_t> in_;
};

}  // namespace gpubridge::usb::emu
