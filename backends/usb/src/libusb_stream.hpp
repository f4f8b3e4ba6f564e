#pragma once
// UsbDevice::bulk_stream on libusb's asynchronous API (one OUT transfer and a queue of IN transfers
// in flight at once, driven by libusb_handle_events on the calling thread).
#include <libusb.h>

#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb {

BulkStreamResult run_libusb_stream(libusb_context* ctx, libusb_device_handle* handle, const BulkStream& s,
                                   const UsbDevice::InSink& on_in);

}  // namespace gpubridge::usb
