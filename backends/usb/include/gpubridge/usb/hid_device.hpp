#pragma once
// The HID transport seam (hidapi semantics): write returns bytes written or -1, read returns
// bytes read, 0 on timeout, -1 on error (a disconnect shows as -1).
#include <cstdint>
#include <span>
#include <string>

namespace gpubridge::usb {

struct HidDeviceInfo {
  std::uint16_t vid = 0, pid = 0;
  std::string path, serial, product;
};

class HidDevice {
 public:
  virtual ~HidDevice() = default;
  virtual const HidDeviceInfo& info() const = 0;
  // data[0] is the report id (0x00 for devices without numbered reports).
  virtual int write(std::span<const std::uint8_t> data) = 0;
  virtual int read(std::span<std::uint8_t> data, int timeout_ms) = 0;
  virtual std::string last_error() const = 0;
};

}  // namespace gpubridge::usb
