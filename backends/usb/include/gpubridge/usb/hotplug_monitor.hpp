#pragma once
// USB arrivals and departures of given VID:PIDs through libusb's hot-plug notifications (udev or
// netlink on Linux). The daemon still polls (a board that is present but not yet accessible, or a
// platform without notifications, is found at the next poll); the notifications only make a plug
// or an unplug take effect within milliseconds instead of at the next interval. MCP2210 adapters
// are found this way too: hidapi-libusb devices are USB devices.
#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "gpubridge/common/result.hpp"

namespace gpubridge::usb {

class HotplugMonitor {
 public:
  // arrived: true for a plug, false for an unplug. Runs on the monitor's own thread: hand the
  // event to your own thread (it must not block, and must not call back into the monitor).
  using Callback = std::function<void(bool arrived, std::uint16_t vid, std::uint16_t pid)>;

  // Starts watching `ids` (duplicates allowed). Errors: libusb cannot start, or this libusb has no
  // hot-plug support (UsbStatus::NotSupported, "...: polling only") — callers then rely on polling.
  static Result<std::unique_ptr<HotplugMonitor>> start(const std::vector<std::pair<std::uint16_t, std::uint16_t>>& ids,
                                                       Callback callback);
  // Stops the thread; no callback runs after this returns.
  ~HotplugMonitor();
  HotplugMonitor(const HotplugMonitor&) = delete;
  HotplugMonitor& operator=(const HotplugMonitor&) = delete;

  struct State;

 private:
  explicit HotplugMonitor(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace gpubridge::usb
