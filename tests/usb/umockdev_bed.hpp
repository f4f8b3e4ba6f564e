#pragma once
// A umockdev testbed holding one FT232H whose usbfs ioctls are answered by the byte-exact MPSSE
// model (driving the reference SPI target), so the real LibusbContext/LibusbDevice code path runs
// against it. Optionally created unplugged (plug() adds the device later). Used by umockdev_test.cpp
// and umockdev_auto_attach_test.cpp; template: libusb tests/umockdev.c.
#include <atomic>
#include <cerrno>
#include <cstring>
#include <deque>
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
  std::deque<UMockdevIoctlData*> done;  // completed URBs waiting to be reaped
  std::atomic<unsigned> control_urbs{0}, bulk_urbs{0};  // written on umockdev's ioctl thread

  static gboolean on_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer self) {
    return static_cast<Bed*>(self)->handle(client);
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
        auto* urb = reinterpret_cast<usbdevfs_urb*>(urb_data->data);
        UMockdevIoctlData* buf =
            umockdev_ioctl_data_resolve(urb_data, G_STRUCT_OFFSET(usbdevfs_urb, buffer), static_cast<gsize>(urb->buffer_length), nullptr);
        auto* bytes = reinterpret_cast<std::uint8_t*>(buf->data);
        UsbIo io;
        if (urb->type == USBDEVFS_URB_TYPE_CONTROL) {
          ++control_urbs;
          const std::uint8_t rt = bytes[0], req = bytes[1];
          const std::uint16_t value = static_cast<std::uint16_t>(bytes[2] | bytes[3] << 8);
          const std::uint16_t index = static_cast<std::uint16_t>(bytes[4] | bytes[5] << 8);
          const std::size_t len = static_cast<std::size_t>(bytes[6] | bytes[7] << 8);
          if (rt & 0x80) io = model.control_in(rt, req, value, index, std::span(bytes + 8, len), 1000);
          else io = model.control_out(rt, req, value, index, std::span<const std::uint8_t>(bytes + 8, len), 1000);
        } else {
          ++bulk_urbs;
          const std::size_t len = static_cast<std::size_t>(urb->buffer_length);
          if (urb->endpoint & 0x80) io = model.bulk_in(urb->endpoint, std::span(bytes, len), 1000);
          else io = model.bulk_out(urb->endpoint, std::span<const std::uint8_t>(bytes, len), 1000);
        }
        urb->actual_length = static_cast<int>(io.transferred);
        urb->status = -errno_of(io.status);
        umockdev_ioctl_data_unref(buf);
        done.push_back(urb_data);
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      }
      case USBDEVFS_REAPURB:
      case USBDEVFS_REAPURBNDELAY: {
        if (done.empty()) {
          umockdev_ioctl_client_complete(client, -1, EAGAIN);
          return TRUE;
        }
        UMockdevIoctlData* urb_data = done.front();
        done.pop_front();
        UMockdevIoctlData* ptr = umockdev_ioctl_data_resolve(arg, 0, sizeof(gpointer), nullptr);
        umockdev_ioctl_data_set_ptr(ptr, 0, urb_data);
        umockdev_ioctl_data_unref(ptr);
        umockdev_ioctl_data_unref(urb_data);
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      }
      case USBDEVFS_DISCARDURB:
        umockdev_ioctl_client_complete(client, -1, EINVAL);
        return TRUE;
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
    g_clear_object(&handler);
    g_clear_object(&testbed);
  }
};

}  // namespace gpubridge::usb::testing
