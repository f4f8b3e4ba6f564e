#include "gpubridge/usb/emu/ch341a_model.hpp"

#include <algorithm>

#include "gpubridge/usb/ch341a.hpp"

namespace gpubridge::usb::emu {

Ch341aModel::Ch341aModel(SpiPins* pins, std::string serial) : UsbChipModel(pins) {
  info_.vid = 0x1a86;
  info_.pid = 0x5512;
  info_.bcd_device = 0x0304;
  info_.product = "CH341A (model)";
  info_.serial = std::move(serial);
  info_.port_path = "1-3";
}

UsbIo Ch341aModel::control_out(std::uint8_t, std::uint8_t, std::uint16_t, std::uint16_t, std::span<const std::uint8_t>, unsigned) {
  violation("the CH341A SPI path uses no control requests");
  return {UsbStatus::Pipe, 0};
}
UsbIo Ch341aModel::control_in(std::uint8_t, std::uint8_t, std::uint16_t, std::uint16_t, std::span<std::uint8_t>, unsigned) {
  violation("the CH341A SPI path uses no control requests");
  return {UsbStatus::Pipe, 0};
}
std::uint16_t Ch341aModel::max_packet_size(std::uint8_t ep) const { return (ep == 0x02 || ep == 0x82) ? 32 : 0; }

void Ch341aModel::update_cs() {
  if (!pins_) return;
  const bool low = (dir_ & 1) && !(uio_ & 1);
  if (low != pins_->cs_asserted()) pins_->set_cs(low);
}

void Ch341aModel::packet(std::span<const std::uint8_t> p) {
  switch (p[0]) {
    case 0xA8:
      if ((dir_ & 0x29) != 0x29) violation("A8 SPI stream before CS/SCK/DOUT were enabled as outputs");
      for (std::size_t i = 1; i < p.size(); ++i) {
        const std::uint8_t wire = reverse_bits(p[i]);  // the chip shifts LSB first
        const std::uint8_t got = pins_ ? pins_->shift_byte(wire) : 0xFF;
        in_.push_back(reverse_bits(got));
      }
      break;
    case 0xAB:
      for (std::size_t i = 1; i < p.size(); ++i) {
        const std::uint8_t c = p[i];
        if (c == 0x20) return;  // end of UIO stream: rest of the packet ignored
        if ((c & 0xC0) == 0x80) uio_ = c & 0x3F;
        else if ((c & 0xC0) == 0x40) dir_ = c & 0x3F;
        else if ((c & 0xC0) == 0xC0) continue;  // delay
        else if (c == 0x00) in_.push_back(uio_);
        else violation("unknown UIO sub-command");
        update_cs();
      }
      violation("UIO stream without 0x20 end marker");
      break;
    case 0xAA:
      if (p.size() < 3 || (p[1] & 0xF0) != 0x60 || p[2] != 0x00) violation("malformed AA configuration stream");
      break;
    default:
      violation("unknown CH341A command byte");
  }
}

UsbIo Ch341aModel::bulk_out(std::uint8_t ep, std::span<const std::uint8_t> data, unsigned) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice) return {UsbStatus::NoDevice, 0};
  if (f == UsbFault::Stall) return {UsbStatus::Pipe, 0};
  if (ep != 0x02 || !claimed_) return {UsbStatus::Io, 0};
  std::size_t accepted = data.size();
  if (f == UsbFault::TimeoutPartial) accepted = std::min(accepted, faults_.partial_bytes);
  for (std::size_t off = 0; off < accepted; off += 32) {
    if (in_.size() > kInBufferBytes) return {UsbStatus::Timeout, off};  // echo bytes never read: chip stalls
    packet(data.subspan(off, std::min<std::size_t>(32, accepted - off)));
  }
  if (f == UsbFault::TimeoutPartial) return {UsbStatus::Timeout, accepted};
  return {UsbStatus::Ok, data.size()};
}

UsbIo Ch341aModel::bulk_in(std::uint8_t ep, std::span<std::uint8_t> data, unsigned) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice) return {UsbStatus::NoDevice, 0};
  if (f == UsbFault::Stall) return {UsbStatus::Pipe, 0};
  if (ep != 0x82 || !claimed_) return {UsbStatus::Io, 0};
  if (in_.empty() || f == UsbFault::TimeoutPartial) return {UsbStatus::Timeout, 0};
  std::size_t n = std::min(data.size(), in_.size());
  if (data.size() % 32 != 0 && in_.size() > data.size()) return {UsbStatus::Overflow, 0};
  for (std::size_t i = 0; i < n; ++i) {
    data[i] = in_.front();
    in_.pop_front();
  }
  return {UsbStatus::Ok, n};
}

}  // namespace gpubridge::usb::emu
