#pragma once
// CP2130 model behind the UsbDevice seam: vendor requests 0x25 (chip select) and 0x31 (SPI word),
// bulk commands with the 8-byte header on OUT 0x01, read data on IN 0x82 (64-byte packets). Each
// bulk command asserts the selected CS for its whole length.
#include <deque>
#include <string>
#include <vector>

#include "gpubridge/usb/emu/fault_plan.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"
#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb::emu {

class Cp2130Model final : public UsbDevice {
 public:
  Cp2130Model(SpiSlave* slave, std::string serial);
  const UsbDeviceInfo& info() const override { return info_; }
  UsbStatus detach_kernel_driver(int interface) override;
  UsbStatus claim_interface(int interface) override;
  UsbStatus release_interface(int interface) override;
  UsbIo control_out(std::uint8_t request_type, std::uint8_t request, std::uint16_t value, std::uint16_t index,
                    std::span<const std::uint8_t> data, unsigned timeout_ms) override;
  UsbIo control_in(std::uint8_t request_type, std::uint8_t request, std::uint16_t value, std::uint16_t index,
                   std::span<std::uint8_t> data, unsigned timeout_ms) override;
  UsbIo bulk_out(std::uint8_t endpoint, std::span<const std::uint8_t> data, unsigned timeout_ms) override;
  UsbIo bulk_in(std::uint8_t endpoint, std::span<std::uint8_t> data, unsigned timeout_ms) override;
  UsbStatus clear_halt(std::uint8_t endpoint) override;
  std::uint16_t max_packet_size(std::uint8_t endpoint) const override;

  FaultPlan& faults() { return faults_; }
  const std::vector<std::string>& violations() const { return violations_; }

 private:
  SpiSlave* slave_;
  UsbDeviceInfo info_;
  FaultPlan faults_;
  std::vector<std::string> violations_;
  bool claimed_ = false;
  int cs_channel_ = -1;
  std::uint8_t spi_word_[11] = {};
  std::deque<std::uint8_t> in_;
};

}  // namespace gpubridge::usb::emu
