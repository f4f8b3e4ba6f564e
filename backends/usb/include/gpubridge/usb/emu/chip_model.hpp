#pragma once
// What every byte-exact bridge chip model shares: the transport it stands behind (a UsbDevice, or
// a HidDevice for HID chips), the FPGA's SPI pins it drives, the USB fault schedule, and the list
// of requests a real chip would refuse or a correct driver never makes (violations: a correct
// driver produces none). The table in bridge_chips.cpp builds one model per chip.
#include <string>
#include <vector>

#include "gpubridge/usb/emu/fault_plan.hpp"
#include "gpubridge/usb/emu/spi_pins.hpp"
#include "gpubridge/usb/hid_device.hpp"
#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb::emu {

class ChipModel {
 public:
  virtual ~ChipModel() = default;
  // The transport the driver talks to: usb() for libusb chips, hid() for HID chips.
  virtual UsbDevice* usb() { return nullptr; }
  virtual HidDevice* hid() { return nullptr; }

  FaultPlan& faults() { return faults_; }
  const std::vector<std::string>& violations() const { return violations_; }

 protected:
  explicit ChipModel(SpiPins* pins) : pins_(pins) {}
  void violation(std::string what) { violations_.push_back(std::move(what)); }

  SpiPins* pins_;  // nullptr: nothing attached to the SPI pins (MISO reads high)
  FaultPlan faults_;
  std::vector<std::string> violations_;
};

// A libusb chip with a single interface (0) and no kernel driver bound to it: claiming, releasing
// and clearing a halt answer as the real chip does, and NO_DEVICE once it is unplugged. Chips with
// more interfaces (FTDI dual-channel parts) override these.
class UsbChipModel : public ChipModel, public UsbDevice {
 public:
  UsbDevice* usb() override { return this; }
  UsbStatus detach_kernel_driver(int interface) override;
  UsbStatus claim_interface(int interface) override;
  UsbStatus release_interface(int interface) override;
  UsbStatus clear_halt(std::uint8_t endpoint) override;

 protected:
  using ChipModel::ChipModel;
  bool claimed_ = false;
};

}  // namespace gpubridge::usb::emu
