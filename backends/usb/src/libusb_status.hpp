#pragma once
// libusb return codes and transfer states as UsbStatus (shared by the synchronous and streaming paths).
#include <libusb.h>

#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb {

inline UsbStatus status_of(int rc) {
  switch (rc) {
    case LIBUSB_SUCCESS: return UsbStatus::Ok;
    case LIBUSB_ERROR_IO: return UsbStatus::Io;
    case LIBUSB_ERROR_INVALID_PARAM: return UsbStatus::InvalidParam;
    case LIBUSB_ERROR_ACCESS: return UsbStatus::Access;
    case LIBUSB_ERROR_NO_DEVICE: return UsbStatus::NoDevice;
    case LIBUSB_ERROR_NOT_FOUND: return UsbStatus::NotFound;
    case LIBUSB_ERROR_BUSY: return UsbStatus::Busy;
    case LIBUSB_ERROR_TIMEOUT: return UsbStatus::Timeout;
    case LIBUSB_ERROR_OVERFLOW: return UsbStatus::Overflow;
    case LIBUSB_ERROR_PIPE: return UsbStatus::Pipe;
    case LIBUSB_ERROR_INTERRUPTED: return UsbStatus::Interrupted;
    case LIBUSB_ERROR_NO_MEM: return UsbStatus::NoMem;
    case LIBUSB_ERROR_NOT_SUPPORTED: return UsbStatus::NotSupported;
    default: return UsbStatus::Other;
  }
}

inline UsbStatus status_of_transfer(libusb_transfer_status s) {
  switch (s) {
    case LIBUSB_TRANSFER_COMPLETED: return UsbStatus::Ok;
    case LIBUSB_TRANSFER_TIMED_OUT: return UsbStatus::Timeout;
    case LIBUSB_TRANSFER_STALL: return UsbStatus::Pipe;
    case LIBUSB_TRANSFER_NO_DEVICE: return UsbStatus::NoDevice;
    case LIBUSB_TRANSFER_OVERFLOW: return UsbStatus::Overflow;
    case LIBUSB_TRANSFER_CANCELLED: return UsbStatus::Interrupted;
    case LIBUSB_TRANSFER_ERROR: return UsbStatus::Io;
  }
  return UsbStatus::Other;
}

}  // namespace gpubridge::usb
