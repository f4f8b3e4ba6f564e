#pragma once
// The usbfs side both umockdev testbeds share (umockdev_bed.hpp: FT232H, umockdev_hid_test.cpp:
// MCP2210): URBs that stay in flight until the device model has something for them, completed and
// cancelled URBs waiting to be reaped, and the answers to REAPURB, DISCARDURB and
// GET_CAPABILITIES. A testbed owns one UrbQueue and runs it on umockdev's ioctl thread.
#include <cerrno>
#include <cstddef>
#include <deque>
#include <functional>
#include <linux/usbdevice_fs.h>

#include <umockdev.h>

namespace gpubridge::usb::testing {

struct UrbQueue {
  std::deque<UMockdevIoctlData*> flying;     // submitted, not completed (in submission order)
  std::deque<UMockdevIoctlData*> done;       // completed, waiting to be reaped
  std::deque<UMockdevIoctlData*> discarded;  // cancelled, waiting to be reaped (-ENOENT)

  UrbQueue() = default;
  UrbQueue(const UrbQueue&) = delete;
  UrbQueue& operator=(const UrbQueue&) = delete;
  ~UrbQueue() { clear(); }
  // Drops every URB; a testbed calls it before it destroys its ioctl handler.
  void clear() {
    for (auto* list : {&flying, &done, &discarded}) {
      for (auto* d : *list) umockdev_ioctl_data_unref(d);
      list->clear();
    }
  }

  static usbdevfs_urb& urb_of(UMockdevIoctlData* d) { return *reinterpret_cast<usbdevfs_urb*>(d->data); }

  void finish(UMockdevIoctlData* d, int status, std::size_t length) {
    urb_of(d).status = status;
    urb_of(d).actual_length = static_cast<int>(length);
    done.push_back(d);
  }

  // Takes a URB out of `flying` and completes it.
  void finish_flying(std::deque<UMockdevIoctlData*>::iterator it, int status, std::size_t length) {
    UMockdevIoctlData* d = *it;
    flying.erase(it);
    finish(d, status, length);
  }

  // REAPURB(NDELAY): a cancelled URB first, then a completed one; when there is none, `advance`
  // (time passing on the bus) gets a chance to complete one, else EAGAIN.
  void reap(UMockdevIoctlClient* client, UMockdevIoctlData* arg, const std::function<void()>& advance) {
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

  // DISCARDURB: a URB still in flight is cancelled; one already completed is reaped normally (EINVAL).
  void discard(UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
    const auto client_addr = reinterpret_cast<gulong>(*reinterpret_cast<void**>(arg->data));
    for (auto it = flying.begin(); it != flying.end(); ++it) {
      if ((*it)->client_addr != client_addr) continue;
      discarded.push_back(*it);
      flying.erase(it);
      umockdev_ioctl_client_complete(client, 0, 0);
      return;
    }
    umockdev_ioctl_client_complete(client, -1, EINVAL);
  }

  // The ioctls whose answers do not depend on the device (no kernel driver bound, reaping,
  // cancelling); false for every other request.
  bool handle_common(unsigned long request, UMockdevIoctlClient* client, UMockdevIoctlData* arg,
                     const std::function<void()>& advance) {
    switch (request) {
      case USBDEVFS_GETDRIVER:
        umockdev_ioctl_client_complete(client, -1, ENODATA);
        return true;
      case USBDEVFS_REAPURB:
      case USBDEVFS_REAPURBNDELAY:
        reap(client, arg, advance);
        return true;
      case USBDEVFS_DISCARDURB:
        discard(client, arg);
        return true;
      default:
        return false;
    }
  }

  static void capabilities(UMockdevIoctlClient* client, UMockdevIoctlData* arg, guint32 caps) {
    UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(guint32), nullptr);
    *reinterpret_cast<guint32*>(d->data) = caps;
    umockdev_ioctl_data_unref(d);
    umockdev_ioctl_client_complete(client, 0, 0);
  }
};

}  // namespace gpubridge::usb::testing
