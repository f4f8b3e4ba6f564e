#include "gpubridge/usb/emu/chip_model.hpp"

namespace gpubridge::usb::emu {

UsbStatus UsbChipModel::detach_kernel_driver(int) {
  return faults_.next() == UsbFault::NoDevice ? UsbStatus::NoDevice : UsbStatus::NotFound;
}
UsbStatus UsbChipModel::claim_interface(int interface) {
  if (faults_.next() == UsbFault::NoDevice) return UsbStatus::NoDevice;
  if (interface != 0) return UsbStatus::NotFound;
  claimed_ = true;
  return UsbStatus::Ok;
}
UsbStatus UsbChipModel::release_interface(int) {
  claimed_ = false;
  return faults_.unplugged ? UsbStatus::NoDevice : UsbStatus::Ok;
}
UsbStatus UsbChipModel::clear_halt(std::uint8_t) { return faults_.unplugged ? UsbStatus::NoDevice : UsbStatus::Ok; }

}  // namespace gpubridge::usb::emu
