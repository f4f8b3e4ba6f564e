#pragma once
// A umockdev testbed holding one FT232H whose usbfs ioctls are answered by the byte-exact MPSSE
// model (driving the reference SPI target), so the real LibusbContext/LibusbDevice code path runs
// against it. Optionally created unplugged (plug() adds the device later). Used by umockdev_test.cpp
// and umockdev_auto_attach_test.cpp; template: libusb tests/umockdev.c.
#include <atomic>
#include <cerrno>
#include <cstring>
#include <map>
#include <vector>
#include <linux/ioctl.h>
#include <linux/usbdevice_fs.h>
#include <sys/ioctl.h>

#include <umockdev.h>

#include "gpubridge/usb/emu/mpsse_model.hpp"
#include "gpubridge/usb/emu/reference_target.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"
#include "gpubridge/usb/usb_device.hpp"
#include "umockdev_urbs.hpp"

namespace gpubridge::usb::testing {

inline int errno_of(UsbStatus s) {
  switch (s) {
    case UsbStatus::Ok: return 0;
    case UsbStatus::NoDevice: return ENODEV;
    case UsbStatus::Pipe: return EPIPE;
    case UsbStatus::Timeout: return ETIMEDOUT;
    case UsbStatus::Overflow: return EOVERFLOW;
    default: return EIO;
  }
}

struct Bed {
  emu::ReferenceTarget target{emu::ReferenceTargetConfig{}};
  emu::SpiSlave slave{target, nullptr, [this] { target.tick(); }};
  emu::MpsseModel model{emu::MpsseModelConfig{}, &slave};
  UMockdevTestbed* testbed = nullptr;
  UMockdevIoctlBase* handler = nullptr;

  // Bulk URBs stay in flight like on a real bus: an OUT URB completes once the chip has taken all
  // of it (its TX FIFO refuses bytes while the MPSSE is stalled on a full RX FIFO), an IN URB when
  // the chip has something for it (a status-only packet at worst). They advance whenever libusb
  // reaps, in submission order per direction.
  UrbQueue urbs;
  struct OutPayload {
    std::vector<std::uint8_t> bytes;  // copied at submission
    std::size_t taken = 0;            // bytes the chip has accepted so far
  };
  std::map<UMockdevIoctlData*, OutPayload> out_payload;
  // Written on umockdev's ioctl thread, read by the test.
  std::atomic<unsigned> control_urbs{0}, bulk_urbs{0};
  std::atomic<unsigned> max_in_flight{0};  // most IN URBs queued at once
  std::atomic<unsigned> out_refusals{0};   // times an OUT URB had to wait for the chip to drain

  static gboolean on_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer self) {
    return static_cast<Bed*>(self)->handle(client);
  }
  static bool is_in(UMockdevIoctlData* d) { return UrbQueue::urb_of(d).endpoint & 0x80; }

  // Lets the chip take OUT data and fill one IN URB, as time passing on a real bus would.
  void advance() {
    for (auto it = urbs.flying.begin(); it != urbs.flying.end(); ++it) {
      if (is_in(*it)) continue;
      OutPayload& out = out_payload[*it];
      const UsbIo io = model.bulk_out(UrbQueue::urb_of(*it).endpoint, std::span<const std::uint8_t>(out.bytes).subspan(out.taken), 1000);
      out.taken += io.transferred;
      if (io.status == UsbStatus::Timeout && out.taken < out.bytes.size()) {
        ++out_refusals;  // TX FIFO full: the URB stays in flight
      } else {
        const std::size_t taken = out.taken;
        out_payload.erase(*it);
        urbs.finish_flying(it, -errno_of(io.status), taken);
      }
      break;
    }
    for (auto it = urbs.flying.begin(); it != urbs.flying.end(); ++it) {
      if (!is_in(*it)) continue;
      usbdevfs_urb& urb = UrbQueue::urb_of(*it);
      UMockdevIoctlData* buf = umockdev_ioctl_data_resolve(*it, G_STRUCT_OFFSET(usbdevfs_urb, buffer),
                                                            static_cast<gsize>(urb.buffer_length), nullptr);
      const UsbIo io = model.bulk_in(urb.endpoint, std::span(reinterpret_cast<std::uint8_t*>(buf->data), buf->data_len), 1000);
      umockdev_ioctl_data_unref(buf);
      urbs.finish_flying(it, -errno_of(io.status), io.transferred);
      break;
    }
  }

  gboolean handle(UMockdevIoctlClient* client) {
    const unsigned long request = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    switch (request) {
      case USBDEVFS_GET_CAPABILITIES:
        UrbQueue::capabilities(client, arg,
                               USBDEVFS_CAP_BULK_SCATTER_GATHER | USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
                                   USBDEVFS_CAP_REAP_AFTER_DISCONNECT | USBDEVFS_CAP_ZERO_PACKET);
        return TRUE;
      case USBDEVFS_CLAIMINTERFACE: {
        const UsbStatus d = model.detach_kernel_driver(0);
        (void)d;
        const UsbStatus s = model.claim_interface(0);
        umockdev_ioctl_client_complete(client, s == UsbStatus::Ok ? 0 : -1, errno_of(s));
        return TRUE;
      }
      case USBDEVFS_RELEASEINTERFACE:
      case USBDEVFS_CLEAR_HALT:
      case USBDEVFS_RESET:
      case USBDEVFS_RESETEP:
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      case USBDEVFS_SUBMITURB: {
        UMockdevIoctlData* urb_data = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_urb), nullptr);
        usbdevfs_urb& urb = UrbQueue::urb_of(urb_data);
        UMockdevIoctlData* buf =
            umockdev_ioctl_data_resolve(urb_data, G_STRUCT_OFFSET(usbdevfs_urb, buffer), static_cast<gsize>(urb.buffer_length), nullptr);
        auto* bytes = reinterpret_cast<std::uint8_t*>(buf->data);
        if (urb.type == USBDEVFS_URB_TYPE_CONTROL) {
          // Control transfers complete at once (the chip answers vendor requests immediately).
          ++control_urbs;
          const std::uint8_t rt = bytes[0], req = bytes[1];
          const std::uint16_t value = static_cast<std::uint16_t>(bytes[2] | bytes[3] << 8);
          const std::uint16_t index = static_cast<std::uint16_t>(bytes[4] | bytes[5] << 8);
          const std::size_t len = static_cast<std::size_t>(bytes[6] | bytes[7] << 8);
          const UsbIo io = (rt & 0x80) ? model.control_in(rt, req, value, index, std::span(bytes + 8, len), 1000)
                                       : model.control_out(rt, req, value, index, std::span<const std::uint8_t>(bytes + 8, len), 1000);
          urbs.finish(urb_data, -errno_of(io.status), io.transferred);
        } else {
          ++bulk_urbs;
          if (!(urb.endpoint & 0x80)) out_payload[urb_data].bytes.assign(bytes, bytes + urb.buffer_length);
          urbs.flying.push_back(urb_data);
          unsigned in_flight = 0;
          for (auto* x : urbs.flying) in_flight += is_in(x) ? 1 : 0;
          if (in_flight > max_in_flight) max_in_flight = in_flight;
        }
        umockdev_ioctl_data_unref(buf);
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      }
      default:
        if (request == USBDEVFS_DISCARDURB)  // a cancelled OUT URB's payload goes with it
          for (auto* d : urbs.flying)
            if (d->client_addr == reinterpret_cast<gulong>(*reinterpret_cast<void**>(arg->data))) out_payload.erase(d);
        return urbs.handle_common(request, client, arg, [this] { advance(); }) ? TRUE : FALSE;
    }
  }

  explicit Bed(bool plugged = true) {
    testbed = umockdev_testbed_new();
    handler = umockdev_ioctl_base_new();
    g_signal_connect(handler, "handle-ioctl", reinterpret_cast<GCallback>(reinterpret_cast<void (*)()>(&Bed::on_ioctl)), this);
    umockdev_testbed_attach_ioctl(testbed, "/dev/bus/usb/001/001", handler, nullptr);
    if (plugged) plug();
  }

  // Adds the FT232H to the testbed: from now on libusb enumerates and opens it.
  // FT232H: 0403:6014 bcdDevice 0x0900, no string descriptors, one interface with bulk 0x81/0x02 (512 bytes).
  void plug() {
    umockdev_testbed_add_from_string(testbed,
                                     "P: /devices/usb1\n"
                                     "N: bus/usb/001/001\n"
                                     "E: SUBSYSTEM=usb\n"
                                     "E: DEVNAME=/dev/bus/usb/001/001\n"
                                     "E: DEVTYPE=usb_device\n"
                                     "E: BUSNUM=001\n"
                                     "E: DEVNUM=001\n"
                                     "A: busnum=1\\n\n"
                                     "A: devnum=1\\n\n"
                                     "A: bConfigurationValue=1\\n\n"
                                     "A: speed=480\\n\n"
                                     "H: descriptors=12010002000000400304146000090000000109022000010100803209040000"
                                     "02ffffff00070581020002000705020200020000\n",
                                     nullptr);
  }

  ~Bed() {
    urbs.clear();
    g_clear_object(&handler);
    g_clear_object(&testbed);
  }
};

}  // namespace gpubridge::usb::testing
