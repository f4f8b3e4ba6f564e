#pragma once
// libusb-1.0 binding of the UsbDevice seam, plus enumeration for `gpubridge probe`. Selection
// order: serial number, then USB port path, then the first match (never bus:address).
#include <memory>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb {

struct UsbMatch {
  std::uint16_t vid = 0, pid = 0;
  std::string serial;     // "" = any
  std::string port_path;  // "" = any
};

struct FoundDevice {
  UsbDeviceInfo info;
  bool accessible = false;
  std::string problem;  // why it cannot be opened (permission, in use), "" when accessible
};

class LibusbContext {
 public:
  static Result<std::shared_ptr<LibusbContext>> create();
  ~LibusbContext();
  LibusbContext(const LibusbContext&) = delete;
  LibusbContext& operator=(const LibusbContext&) = delete;

  // Devices whose VID:PID is in `ids`; each is opened briefly to read the serial and to learn
  // whether we may use it.
  Result<std::vector<FoundDevice>> enumerate(const std::vector<std::pair<std::uint16_t, std::uint16_t>>& ids);
  Result<std::unique_ptr<UsbDevice>> open(const UsbMatch& match);

  struct Raw;  // libusb_context*

 private:
  LibusbContext() = default;
  std::shared_ptr<Raw> raw_;
};

}  // namespace gpubridge::usb
