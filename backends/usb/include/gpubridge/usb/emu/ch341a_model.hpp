#pragma once
// Byte-exact CH341A model behind the UsbDevice seam: 32-byte OUT packets, A8 SPI stream (LSB
// first: the bytes the slave sees are the bit-reversed host bytes), AB UIO stream for pins and
// chip select, AA configuration; echoed bytes on the IN endpoint.
#include <deque>
#include <string>
#include <vector>

#include "gpubridge/usb/emu/fault_plan.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"
#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb::emu {

class Ch341aModel final : public UsbDevice {
 public:
  Ch341aModel(SpiSlave* slave, std::string serial);
  const UsbDeviceInfo& info() const override { return info_; }
  UsbStatus detach_kernel_driver(int interface) override;
  UsbStatus claim_interface(int interface) override;
  UsbStatus release_interface(int interface) override;
  UsbIo control_out(std::uint8_t, std::uint8_t, std::uint16_t, std::uint16_t, std::span<const std::uint8_t>, unsigned) override;
  UsbIo control_in(std::uint8_t, std::uint8_t, std::uint16_t, std::uint16_t, std::span<std::uint8_t>, unsigned) override;
  UsbIo bulk_out(std::uint8_t endpoint, std::span<const std::uint8_t> data, unsigned timeout_ms) override;
  UsbIo bulk_in(std::uint8_t endpoint, std::span<std::uint8_t> data, unsigned timeout_ms) override;
  UsbStatus clear_halt(std::uint8_t endpoint) override;
  std::uint16_t max_packet_size(std::uint8_t endpoint) const override;

  FaultPlan& faults() { return faults_; }
  const std::vector<std::string>& violations() const { return violations_; }
  static constexpr std::size_t kInBufferBytes = 1024;  // unread echo bytes before the chip stalls

 private:
  void packet(std::span<const std::uint8_t> p);
  void update_cs();
  SpiSlave* slave_;
  UsbDeviceInfo info_;
  FaultPlan faults_;
  std::vector<std::string> violations_;
  bool claimed_ = false;
  std::uint8_t pins_ = 0x3F, dir_ = 0;
  std::deque<std::uint8_t> in_;
};

}  // namespace gpubridge::usb::emu
