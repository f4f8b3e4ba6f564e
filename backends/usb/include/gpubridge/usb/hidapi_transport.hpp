#pragma once
// hidapi binding of the HidDevice seam (MCP2210), plus enumeration for `gpubridge probe`.
#include <memory>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/usb/hid_device.hpp"

namespace gpubridge::usb {

class HidapiContext : public std::enable_shared_from_this<HidapiContext> {
 public:
  static Result<std::shared_ptr<HidapiContext>> create();
  ~HidapiContext();
  HidapiContext(const HidapiContext&) = delete;
  HidapiContext& operator=(const HidapiContext&) = delete;

  std::vector<HidDeviceInfo> enumerate(std::uint16_t vid, std::uint16_t pid);
  // Serial first, else the first device with that VID:PID.
  Result<std::unique_ptr<HidDevice>> open(std::uint16_t vid, std::uint16_t pid, const std::string& serial);

 private:
  HidapiContext() = default;
};

}  // namespace gpubridge::usb
