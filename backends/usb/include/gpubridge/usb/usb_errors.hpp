#pragma once
// Turns transport statuses into errors that say what to fix, with BackendError codes so the
// daemon can decide between falling back (kDeviceGone) and retrying (kDeviceTimeout).
#include <string_view>

#include "gpubridge/common/result.hpp"
#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb {

// `what` names the operation and device, e.g. "FT232H 0403:6014 (port 1-2): bulk OUT".
Error usb_error(UsbStatus s, std::string_view what);
// BackendError code for a status (kDeviceGone for NoDevice/Io, kDeviceTimeout for Timeout, ...).
int backend_code(UsbStatus s);

inline constexpr std::string_view kUdevHint =
    "install the udev rules: sudo cp configs/udev/70-gpubridge.rules /etc/udev/rules.d/ && "
    "sudo udevadm control --reload && replug the adapter";

}  // namespace gpubridge::usb
