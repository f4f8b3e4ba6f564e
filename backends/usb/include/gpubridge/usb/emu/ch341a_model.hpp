#pragma once
// Byte-exact CH341A model behind the UsbDevice seam: 32-byte OUT packets, A8 SPI stream (LSB
// first: the bytes the slave sees are the bit-reversed host bytes), AB UIO stream for pins and
// chip select, AA configuration; echoed bytes on the IN endpoint.
#include <deque>
#include <string>
#include <vector>

#include "gpubridge/usb/emu/chip_model.hpp"

namespace gpubridge::usb::emu {

class Ch341aModel final : public UsbChipModel {
 public:
  Ch341aModel(SpiPins* pins, std::string serial);
  const UsbDeviceInfo& info() const override { return info_; }
  UsbIo control_out(std::uint8_t, std::uint8_t, std::uint16_t, std::uint16_t, std::span<const std::uint8_t>, unsigned) override;
  UsbIo control_in(std::uint8_t, std::uint8_t, std::uint16_t, std::uint16_t, std::span<std::uint8_t>, unsigned) override;
  UsbIo bulk_out(std::uint8_t endpoint, std::span<const std::uint8_t> data, unsigned timeout_ms) override;
  UsbIo bulk_in(std::uint8_t endpoint, std::span<std::uint8_t> data, unsigned timeout_ms) override;
  std::uint16_t max_packet_size(std::uint8_t endpoint) const override;

  static constexpr std::size_t kInBufferBytes = 1024;  // unread echo bytes before the chip stalls

 private:
  void packet(std::span<const std::uint8_t> p);
  void update_cs();
  UsbDeviceInfo info_;
  std::uint8_t uio_ = 0x3F, dir_ = 0;  // the UIO pins' levels and directions (D0 = chip select)
  std::deque<std::uint8_t> in_;
};

}  // namespace gpubridge::usb::emu
