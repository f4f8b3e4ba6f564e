#include "gpubridge/usb/emu/cp2130_model.hpp"

#include <algorithm>

namespace gpubridge::usb::emu {

Cp2130Model::Cp2130Model(SpiPins* pins, std::string serial) : UsbChipModel(pins) {
  info_.vid = 0x10c4;
  info_.pid = 0x87a0;
  info_.bcd_device = 0x0100;
  info_.product = "CP2130 (model)";
  info_.serial = std::move(serial);
  info_.port_path = "1-4";
}

std::uint16_t Cp2130Model::max_packet_size(std::uint8_t ep) const {
  return (ep == 0x01 || ep == 0x02 || ep == 0x81 || ep == 0x82) ? 64 : 0;
}

UsbIo Cp2130Model::control_out(std::uint8_t rt, std::uint8_t req, std::uint16_t value, std::uint16_t index,
                               std::span<const std::uint8_t> data, unsigned) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice) return {UsbStatus::NoDevice, 0};
  if (f == UsbFault::Stall) return {UsbStatus::Pipe, 0};
  if (f == UsbFault::TimeoutPartial) return {UsbStatus::Timeout, 0};
  if (rt != kRequestTypeVendorOut || value != 0 || index != 0) {
    violation("CP2130 control request with wrong bmRequestType/wValue/wIndex");
    return {UsbStatus::Pipe, 0};
  }
  switch (req) {
    case 0x25:
      if (data.size() != 2 || data[0] > 10 || data[1] > 2) {
        violation("Set_GPIO_Chip_Select needs [channel 0..10, mode 0..2]");
        return {UsbStatus::Pipe, 0};
      }
      cs_channel_ = data[1] == 0 ? -1 : data[0];
      return {UsbStatus::Ok, 2};
    case 0x31:
      if (data.size() != 2 || data[0] > 10) {
        violation("Set_SPI_Word needs [channel 0..10, word]");
        return {UsbStatus::Pipe, 0};
      }
      spi_word_[data[0]] = data[1];
      return {UsbStatus::Ok, 2};
    case 0x60: case 0x61: case 0x62: case 0x63: case 0x64: case 0x65: case 0x66: case 0x67: case 0x68: case 0x69:
    case 0x6A: case 0x6B: case 0x6C: case 0x6D: case 0x6E: case 0x6F: case 0x70: case 0x71:
      violation("one-time-programmable configuration request: never write these");
      return {UsbStatus::Pipe, 0};
    default:
      violation("unsupported CP2130 request");
      return {UsbStatus::Pipe, 0};
  }
}

UsbIo Cp2130Model::control_in(std::uint8_t, std::uint8_t, std::uint16_t, std::uint16_t, std::span<std::uint8_t>, unsigned) {
  if (faults_.next() == UsbFault::NoDevice) return {UsbStatus::NoDevice, 0};
  return {UsbStatus::Pipe, 0};
}

UsbIo Cp2130Model::bulk_out(std::uint8_t ep, std::span<const std::uint8_t> data, unsigned) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice) return {UsbStatus::NoDevice, 0};
  if (f == UsbFault::Stall) return {UsbStatus::Pipe, 0};
  if (ep != 0x01 || !claimed_) return {UsbStatus::Io, 0};
  std::size_t accepted = data.size();
  if (f == UsbFault::TimeoutPartial) accepted = std::min(accepted, faults_.partial_bytes);
  if (accepted < 8) return {UsbStatus::Timeout, accepted};  // header incomplete: nothing clocked
  const std::uint8_t cmd = data[2];
  const std::size_t len = std::size_t{data[4]} | std::size_t{data[5]} << 8 | std::size_t{data[6]} << 16 | std::size_t{data[7]} << 24;
  if (data[0] != 0 || data[1] != 0 || data[3] != 0 || (cmd != 0x00 && cmd != 0x01 && cmd != 0x02 && cmd != 0x04)) {
    violation("malformed CP2130 bulk command header");
    return {UsbStatus::Pipe, 0};
  }
  if ((cmd == 0x01 || cmd == 0x02) && data.size() != 8 + len) {
    violation("bulk command length field does not match the data sent");
    return {UsbStatus::Pipe, 0};
  }
  if (cmd == 0x02 && len > 56) violation("WriteRead over 56 bytes stalls the synchronous API (single-buffered IN)");
  if (cs_channel_ < 0) violation("SPI command with no chip select enabled");
  if (cs_channel_ >= 0 && (spi_word_[cs_channel_] & 0x30) != 0) violation("CS channel not in SPI mode 0");
  if (pins_) pins_->set_cs(true);
  const std::size_t clocked = std::min(len, accepted - 8);
  for (std::size_t i = 0; i < clocked; ++i) {
    const std::uint8_t got = pins_ ? pins_->shift_byte(data[8 + i]) : 0xFF;
    if (cmd == 0x02) in_.push_back(got);
  }
  if (pins_) pins_->set_cs(false);
  if (f == UsbFault::TimeoutPartial) return {UsbStatus::Timeout, accepted};
  return {UsbStatus::Ok, data.size()};
}

UsbIo Cp2130Model::bulk_in(std::uint8_t ep, std::span<std::uint8_t> data, unsigned) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice) return {UsbStatus::NoDevice, 0};
  if (f == UsbFault::Stall) return {UsbStatus::Pipe, 0};
  if (ep != 0x82 || !claimed_) return {UsbStatus::Io, 0};
  if (in_.empty() || f == UsbFault::TimeoutPartial) return {UsbStatus::Timeout, 0};
  const std::size_t n = std::min({data.size(), in_.size(), std::size_t{64}});
  for (std::size_t i = 0; i < n; ++i) {
    data[i] = in_.front();
    in_.pop_front();
  }
  return {UsbStatus::Ok, n};
}

}  // namespace gpubridge::usb::emu
