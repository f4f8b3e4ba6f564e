#pragma once
// The USB transport seam. Every bridge driver talks to its chip only through UsbDevice (or
// HidDevice for HID bridges): production binds it to libusb, tests and emulated boards bind it
// to byte-exact chip models. Status codes mirror libusb's so both sides report the same faults.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace gpubridge::usb {

enum class UsbStatus : int {
  Ok = 0,
  Io = -1,
  InvalidParam = -2,
  Access = -3,
  NoDevice = -4,
  NotFound = -5,
  Busy = -6,
  Timeout = -7,
  Overflow = -8,
  Pipe = -9,
  Interrupted = -10,
  NoMem = -11,
  NotSupported = -12,
  Other = -99,
};
std::string_view to_string(UsbStatus s);

// Outcome of one transfer. A timeout may still have moved `transferred` bytes (libusb semantics).
struct UsbIo {
  UsbStatus status = UsbStatus::Ok;
  std::size_t transferred = 0;
  bool ok() const { return status == UsbStatus::Ok; }
};

// What enumeration tells us about a device, before or after opening it.
struct UsbDeviceInfo {
  std::uint16_t vid = 0, pid = 0, bcd_device = 0;
  std::string serial;        // "" when unreadable (no permission) or absent
  std::string manufacturer, product;
  std::string port_path;     // "bus-port.port..." (stable across re-plugs, unlike bus:address)
  std::uint8_t bus = 0, address = 0;
  bool high_speed = false;
};

inline constexpr std::uint8_t kRequestTypeVendorOut = 0x40;  // host-to-device, vendor, device
inline constexpr std::uint8_t kRequestTypeVendorIn = 0xC0;   // device-to-host, vendor, device

class UsbDevice {
 public:
  virtual ~UsbDevice() = default;
  virtual const UsbDeviceInfo& info() const = 0;
  // NotFound / NotSupported mean "no kernel driver bound": callers tolerate them.
  virtual UsbStatus detach_kernel_driver(int interface) = 0;
  virtual UsbStatus claim_interface(int interface) = 0;
  virtual UsbStatus release_interface(int interface) = 0;
  virtual UsbIo control_out(std::uint8_t request_type, std::uint8_t request, std::uint16_t value,
                            std::uint16_t index, std::span<const std::uint8_t> data, unsigned timeout_ms) = 0;
  virtual UsbIo control_in(std::uint8_t request_type, std::uint8_t request, std::uint16_t value,
                           std::uint16_t index, std::span<std::uint8_t> data, unsigned timeout_ms) = 0;
  virtual UsbIo bulk_out(std::uint8_t endpoint, std::span<const std::uint8_t> data, unsigned timeout_ms) = 0;
  virtual UsbIo bulk_in(std::uint8_t endpoint, std::span<std::uint8_t> data, unsigned timeout_ms) = 0;
  virtual UsbStatus clear_halt(std::uint8_t endpoint) = 0;
  // wMaxPacketSize from the endpoint descriptor (0 if the endpoint does not exist).
  virtual std::uint16_t max_packet_size(std::uint8_t endpoint) const = 0;
};

}  // namespace gpubridge::usb
