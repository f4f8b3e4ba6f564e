#pragma once
// USB-level fault schedule shared by the chip models: every transport operation (control,
// bulk, HID report) gets the next index; a fault fires at a chosen index so a test can sweep
// the index through a whole session (reliability-tests.md section 4).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>

namespace gpubridge::usb::emu {

enum class UsbFault : std::uint8_t {
  None,
  NoDevice,        // this and every later operation fails with NO_DEVICE (unplug)
  TimeoutPartial,  // the transfer moves `partial_bytes` then times out
  Stall,           // PIPE once
};

struct FaultPlan {
  std::optional<std::uint64_t> at_op;
  UsbFault fault = UsbFault::None;
  std::size_t partial_bytes = 0;

  // Unplug from outside the process (emulated hot-plug): when non-empty, the device counts as
  // plugged in only while this file exists. Once it is found missing the device stays gone (like a
  // real libusb handle after an unplug); a replug is a new device that must be opened again.
  std::string presence_file;

  std::uint64_t ops = 0;  // operations seen so far
  bool unplugged = false;

  bool present() const {
    if (presence_file.empty()) return true;
    std::error_code ec;
    return std::filesystem::exists(presence_file, ec);
  }

  // Called by a model at the start of every operation; returns the fault to apply now.
  UsbFault next() {
    const std::uint64_t op = ops++;
    if (!unplugged && !present()) unplugged = true;
    if (unplugged) return UsbFault::NoDevice;
    if (at_op && *at_op == op) {
      if (fault == UsbFault::NoDevice) unplugged = true;
      return fault;
    }
    return UsbFault::None;
  }
};

}  // namespace gpubridge::usb::emu
