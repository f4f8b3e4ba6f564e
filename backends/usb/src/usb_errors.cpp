#include "gpubridge/usb/usb_errors.hpp"

#include <string>

#include "gpubridge/backends/backend.hpp"

namespace gpubridge::usb {

std::string_view to_string(UsbStatus s) {
  switch (s) {
    case UsbStatus::Ok: return "ok";
    case UsbStatus::Io: return "I/O error";
    case UsbStatus::InvalidParam: return "invalid parameter";
    case UsbStatus::Access: return "access denied";
    case UsbStatus::NoDevice: return "no device (unplugged)";
    case UsbStatus::NotFound: return "not found";
    case UsbStatus::Busy: return "busy";
    case UsbStatus::Timeout: return "timeout";
    case UsbStatus::Overflow: return "overflow (device sent more than requested)";
    case UsbStatus::Pipe: return "pipe error (endpoint stalled)";
    case UsbStatus::Interrupted: return "interrupted";
    case UsbStatus::NoMem: return "out of memory";
    case UsbStatus::NotSupported: return "not supported";
    case UsbStatus::Other: return "unknown error";
  }
  return "unknown error";
}

int backend_code(UsbStatus s) {
  switch (s) {
    case UsbStatus::NoDevice:
    case UsbStatus::Io:  // libusb may report an unplug mid-transfer as IO (cp2130-conf)
      return backends::kDeviceGone;
    case UsbStatus::Timeout:
      return backends::kDeviceTimeout;
    default:
      return backends::kDeviceProtocol;
  }
}

Error usb_error(UsbStatus s, std::string_view what) {
  std::string msg(what);
  msg += ": ";
  msg += to_string(s);
  switch (s) {
    case UsbStatus::Access:
      msg += " — no permission to open the USB device; ";
      msg += kUdevHint;
      break;
    case UsbStatus::Busy:
      msg += " — interface in use: a kernel driver (ftdi_sio, ch341, cp210x) is attached or another process "
             "(openFPGALoader, iceprog, another gpubridged) holds it; close that process or unbind the driver";
      break;
    case UsbStatus::NoDevice:
      msg += " — the adapter was unplugged; replug it (the board will be re-attached by serial number)";
      break;
    case UsbStatus::Timeout:
      msg += " — the bridge did not complete the transfer in time; device state is unknown and will be resynchronised";
      break;
    case UsbStatus::Pipe:
      msg += " — the chip rejected the request; check the board profile's chip type and interface";
      break;
    case UsbStatus::NotFound:
      msg += " — check the VID:PID, serial or port path in the board profile";
      break;
    default:
      break;
  }
  return make_error(std::move(msg), backend_code(s));
}

}  // namespace gpubridge::usb
