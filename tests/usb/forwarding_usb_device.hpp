#pragma once
// A UsbDevice that passes every call to another one, for tests that change one behaviour of a
// chip model's transport (override that call). bulk_stream is deliberately not forwarded: the
// driver sees a device with synchronous transfers only (UsbDevice's default says NotSupported).
#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb::testing {

class ForwardingUsbDevice : public UsbDevice {
 public:
  explicit ForwardingUsbDevice(UsbDevice& inner) : in_(inner) {}
  const UsbDeviceInfo& info() const override { return in_.info(); }
  UsbStatus detach_kernel_driver(int i) override { return in_.detach_kernel_driver(i); }
  UsbStatus claim_interface(int i) override { return in_.claim_interface(i); }
  UsbStatus release_interface(int i) override { return in_.release_interface(i); }
  UsbIo control_out(std::uint8_t rt, std::uint8_t rq, std::uint16_t v, std::uint16_t i, std::span<const std::uint8_t> d,
                    unsigned t) override {
    return in_.control_out(rt, rq, v, i, d, t);
  }
  UsbIo control_in(std::uint8_t rt, std::uint8_t rq, std::uint16_t v, std::uint16_t i, std::span<std::uint8_t> d, unsigned t) override {
    return in_.control_in(rt, rq, v, i, d, t);
  }
  UsbIo bulk_out(std::uint8_t ep, std::span<const std::uint8_t> d, unsigned t) override { return in_.bulk_out(ep, d, t); }
  UsbIo bulk_in(std::uint8_t ep, std::span<std::uint8_t> d, unsigned t) override { return in_.bulk_in(ep, d, t); }
  UsbStatus clear_halt(std::uint8_t ep) override { return in_.clear_halt(ep); }
  std::uint16_t max_packet_size(std::uint8_t ep) const override { return in_.max_packet_size(ep); }

 private:
  UsbDevice& in_;
};

}  // namespace gpubridge::usb::testing
