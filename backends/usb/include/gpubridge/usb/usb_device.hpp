#pragma once
// The USB transport seam. Every bridge driver talks to its chip only through UsbDevice (or
// HidDevice for HID bridges): production binds it to libusb, tests and emulated boards bind it
// to byte-exact chip models. Status codes mirror libusb's so both sides report the same faults.
#include <cstddef>
#include <cstdint>
#include <functional>
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

// A full-duplex bulk stream (see UsbDevice::bulk_stream).
struct BulkStream {
  std::uint8_t out_endpoint = 0, in_endpoint = 0;
  std::span<const std::uint8_t> out;  // sent in order, in transfers of at most out_chunk bytes
  std::size_t out_chunk = 16 * 1024;
  std::size_t in_transfer_bytes = 16 * 1024;  // size of each queued IN transfer
  unsigned in_queue_depth = 4;                // IN transfers kept in flight
  unsigned timeout_ms = 1000;                 // the stream fails when no transfer completes for this long
};

// What the stream's consumer says after each IN transfer.
enum class StreamStep { More, Done, Abort };

struct BulkStreamResult {
  UsbStatus status = UsbStatus::Ok;
  std::size_t out_transferred = 0;
  std::uint64_t out_transfers = 0, in_transfers = 0;
  bool ok() const { return status == UsbStatus::Ok; }
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

  // Sends `s.out` while IN transfers stay queued on `s.in_endpoint`, so a device that stops taking
  // OUT data until the host drains its IN FIFO (an FTDI MPSSE reading more than its RX FIFO) streams
  // at the link rate instead of one round trip per FIFO-full. Every completed IN transfer goes to
  // `on_in` in order (status-only packets included); the stream ends Ok when the OUT data is sent
  // and on_in has said Done, or at once (status Ok, consumer's decision) when on_in says Abort.
  // Transfers still in flight are cancelled and reaped before this returns. Devices without an
  // asynchronous path return NotSupported before sending anything; callers then fall back to
  // synchronous rounds.
  using InSink = std::function<StreamStep(std::span<const std::uint8_t>)>;
  virtual BulkStreamResult bulk_stream(const BulkStream& s, const InSink& on_in) {
    (void)s;
    (void)on_in;
    return {UsbStatus::NotSupported, 0, 0, 0};
  }
};

}  // namespace gpubridge::usb
