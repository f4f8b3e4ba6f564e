#pragma once
// A umockdev testbed holding one FT232H whose usbfs ioctls are answered by the byte-exact MPSSE
// model (driving the reference SPI target), so the real LibusbContext/LibusbDevice code path runs
// against it. Optionally created unplugged (plug() adds the device later). Used by umockdev_test.cpp
// and umockdev_auto_attach_test.cpp; template: libusb tests/umockdev.c.
#include <atomic>
#include <cerrno>
#include <cstring>
#include <deque>
#include <vector>
#include <linux/ioctl.h>
#include <linux/usbdevice_fs.h>
#include <sys/ioctl.h>

#include <umockdev.h>

#include "gpubridge/usb/emu/mpsse_model.hpp"
#include "gpubridge/usb/emu/reference_target.hpp"
#include "gpubridge/usb/usb_device.hpp"

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
  struct Flying {
    UMockdevIoctlData* urb;
    std::vector<std::uint8_t> out;  // OUT payload, copied at submission
    std::size_t taken = 0;          // OUT bytes the chip has accepted so far
  };
  std::deque<Flying> flying;
  std::deque<UMockdevIoctlData*> done;       // completed URBs waiting to be reaped
  std::deque<UMockdevIoctlData*> discarded;  // cancelled URBs waiting to be reaped (-ENOENT)
  // Written on umockdev's ioctl thread, read by the test.
  std::atomic<unsigned> control_urbs{0}, bulk_urbs{0};
  std::atomic<unsigned> max_in_flight{0};  // most IN URBs queued at once
  std::atomic<unsigned> out_refusals{0};   // times an OUT URB had to wait for the chip to drain

  static gboolean on_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer self) {
    return static_cast<Bed*>(self)->handle(client);
  }

  static usbdevfs_urb& urb_of(UMockdevIoctlData* d) { return *reinterpret_cast<usbdevfs_urb*>(d->data); }

  void complete_urb(UMockdevIoctlData* d, const UsbIo& io, std::size_t length) {
    urb_of(d).actual_length = static_cast<int>(length);
    urb_of(d).status = -errno_of(io.status);
    done.push_back(d);
  }

  // Lets the chip take OUT data and fill one IN URB, as time passing on a real bus would.
  void advance() {
    for (auto it = flying.begin(); it != flying.end(); ++it) {
      if (urb_of(it->urb).endpoint & 0x80) continue;
      const UsbIo io = model.bulk_out(urb_of(it->urb).endpoint, std::span<const std::uint8_t>(it->out).subspan(it->taken), 1000);
      it->taken += io.transferred;
      if (io.status == UsbStatus::Timeout && it->taken < it->out.size()) {
        ++out_refusals;  // TX FIFO full: the URB stays in flight
      } else {
        complete_urb(it->urb, io, it->taken);
        flying.erase(it);
      }
      break;
    }
    for (auto it = flying.begin(); it != flying.end(); ++it) {
      usbdevfs_urb& urb = urb_of(it->urb);
      if (!(urb.endpoint & 0x80)) continue;
      UMockdevIoctlData* buf = umockdev_ioctl_data_resolve(it->urb, G_STRUCT_OFFSET(usbdevfs_urb, buffer),
                                                            static_cast<gsize>(urb.buffer_length), nullptr);
      const UsbIo io = model.bulk_in(urb.endpoint, std::span(reinterpret_cast<std::uint8_t*>(buf->data), buf->data_len), 1000);
      umockdev_ioctl_data_unref(buf);
      complete_urb(it->urb, io, io.transferred);
      flying.erase(it);
      break;
    }
  }

  void reap(UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
    if (done.empty() && discarded.empty()) advance();
    UMockdevIoctlData* urb_data = nullptr;
    if (!discarded.empty()) {
      urb_data = discarded.front();
      discarded.pop_front();
      urb_of(urb_data).status = -ENOENT;
    } else if (!done.empty()) {
      urb_data = done.front();
      done.pop_front();
    } else {
      umockdev_ioctl_client_complete(client, -1, EAGAIN);
      return;
    }
    UMockdevIoctlData* ptr = umockdev_ioctl_data_resolve(arg, 0, sizeof(gpointer), nullptr);
    umockdev_ioctl_data_set_ptr(ptr, 0, urb_data);
    umockdev_ioctl_data_unref(ptr);
    umockdev_ioctl_data_unref(urb_data);
    umockdev_ioctl_client_complete(client, 0, 0);
  }

  gboolean handle(UMockdevIoctlClient* client) {
    const unsigned long request = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    switch (request) {
      case USBDEVFS_GET_CAPABILITIES: {
        UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(guint32), nullptr);
        *reinterpret_cast<guint32*>(d->data) = USBDEVFS_CAP_BULK_SCATTER_GATHER | USBDEVFS_CAP_BULK_CONTINUATION |
                                               USBDEVFS_CAP_NO_PACKET_SIZE_LIM | USBDEVFS_CAP_REAP_AFTER_DISCONNECT |
                                               USBDEVFS_CAP_ZERO_PACKET;
        umockdev_ioctl_data_unref(d);
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      }
      case USBDEVFS_GETDRIVER:  // no kernel driver bound
        umockdev_ioctl_client_complete(client, -1, ENODATA);
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
        usbdevfs_urb& urb = urb_of(urb_data);
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
          complete_urb(urb_data, io, io.transferred);
        } else {
          ++bulk_urbs;
          Flying f{urb_data, {}, 0};
          if (!(urb.endpoint & 0x80)) f.out.assign(bytes, bytes + urb.buffer_length);
          flying.push_back(std::move(f));
          unsigned in_flight = 0;
          for (const Flying& x : flying) in_flight += (urb_of(x.urb).endpoint & 0x80) ? 1 : 0;
          if (in_flight > max_in_flight) max_in_flight = in_flight;
        }
        umockdev_ioctl_data_unref(buf);
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      }
      case USBDEVFS_REAPURB:
      case USBDEVFS_REAPURBNDELAY:
        reap(client, arg);
        return TRUE;
      case USBDEVFS_DISCARDURB: {
        const auto client_addr = reinterpret_cast<gulong>(*reinterpret_cast<void**>(arg->data));
        for (auto it = flying.begin(); it != flying.end(); ++it) {
          if (it->urb->client_addr != client_addr) continue;
          discarded.push_back(it->urb);
          flying.erase(it);
          umockdev_ioctl_client_complete(client, 0, 0);
          return TRUE;
        }
        umockdev_ioctl_client_complete(client, -1, EINVAL);  // already completed: libusb reaps it normally
        return TRUE;
      }
      default:
        return FALSE;
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
    for (auto& f : flying) umockdev_ioctl_data_unref(f.urb);
    for (auto* d : done) umockdev_ioctl_data_unref(d);
    for (auto* d : discarded) umockdev_ioctl_data_unref(d);
    g_clear_object(&handler);
    g_clear_object(&testbed);
  }
};

}  // namespace gpubridge::usb::testing
