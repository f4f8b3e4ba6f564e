#include <libusb.h>

#include <algorithm>
#include <atomic>
#include <thread>

#include "gpubridge/common/log.hpp"
#include "gpubridge/usb/hotplug_monitor.hpp"
#include "gpubridge/usb/usb_errors.hpp"
#include "libusb_status.hpp"

namespace gpubridge::usb {

// A context of its own: the event thread below handles only this context's events, so it never
// competes with the synchronous transfers of the drivers (each driver has its own context too).
struct HotplugMonitor::State {
  libusb_context* ctx = nullptr;
  std::vector<libusb_hotplug_callback_handle> handles;
  Callback callback;
  std::atomic<bool> stop{false};
  std::thread events;

  static int LIBUSB_CALL on_event(libusb_context*, libusb_device* dev, libusb_hotplug_event event, void* self) {
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(dev, &d) == 0)
      static_cast<State*>(self)->callback(event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED, d.idVendor, d.idProduct);
    return 0;  // stay registered
  }

  ~State() {
    stop = true;
    if (events.joinable()) events.join();
    for (auto h : handles) libusb_hotplug_deregister_callback(ctx, h);
    if (ctx) libusb_exit(ctx);
  }
};

HotplugMonitor::HotplugMonitor(std::unique_ptr<State> state) : state_(std::move(state)) {}
HotplugMonitor::~HotplugMonitor() = default;

Result<std::unique_ptr<HotplugMonitor>> HotplugMonitor::start(const std::vector<std::pair<std::uint16_t, std::uint16_t>>& ids,
                                                               Callback callback) {
  if (!libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG))
    return usb_error(UsbStatus::NotSupported, "libusb hot-plug notifications (this libusb has none): polling only");
  auto s = std::make_unique<State>();
  s->callback = std::move(callback);
  if (const int rc = libusb_init(&s->ctx); rc != 0) {
    s->ctx = nullptr;
    return usb_error(status_of(rc), "libusb_init for hot-plug notifications");
  }
  auto unique = ids;
  std::sort(unique.begin(), unique.end());
  unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
  for (const auto& [vid, pid] : unique) {
    libusb_hotplug_callback_handle h{};
    const auto events = static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT);
    const int rc = libusb_hotplug_register_callback(s->ctx, events, static_cast<libusb_hotplug_flag>(0), vid, pid,
                                                    LIBUSB_HOTPLUG_MATCH_ANY, &State::on_event, s.get(), &h);
    if (rc != LIBUSB_SUCCESS) return usb_error(status_of(rc), "register a libusb hot-plug callback");
    s->handles.push_back(h);
  }
  // Short waits so the destructor's stop flag is seen within 100 ms.
  s->events = std::thread([state = s.get()] {
    while (!state->stop) {
      timeval tv{0, 100000};
      if (const int rc = libusb_handle_events_timeout_completed(state->ctx, &tv, nullptr);
          rc != 0 && rc != LIBUSB_ERROR_INTERRUPTED) {
        logger("usb")->warn("hot-plug notifications stopped: {} (polling continues)", libusb_error_name(rc));
        return;
      }
    }
  });
  logger("usb")->debug("hot-plug notifications for {} USB id(s)", unique.size());
  return std::unique_ptr<HotplugMonitor>(new HotplugMonitor(std::move(s)));
}

}  // namespace gpubridge::usb
