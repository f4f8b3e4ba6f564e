#pragma once
// Hotplug: the board coming and going (docs/daemon.md "Hot-plug"). Notices an unplugged board
// (a command or the presence probe meets kDeviceGone), switches to the fallback simulator, and
// picks the board up again when it reappears; `auto` that started on the simulator picks up a
// first board the same way. Events to clients and the backend description go through Hooks.
// Threads: the timer and counters live on the network thread, probes and re-attach attempts run
// on the device thread (through DeviceWorker), as does on_device_gone().
#include <chrono>
#include <cstdint>
#include <functional>

#include <nlohmann/json.hpp>

#include "gpubridge/daemon/device_worker.hpp"

namespace gpubridge::daemon {

class Hotplug {
 public:
  using Executor = boost::asio::any_io_executor;
  struct Hooks {
    std::function<void(const backends::DeviceInfo&)> backend_changed;  // network thread
    std::function<void(const nlohmann::json&)> broadcast;               // network thread: a DEVICE_EVENT to all
  };

  Hotplug(Executor net, Executor device, DeviceWorker& worker, BackendFactory fallback, Hooks hooks);
  Hotplug(const Hotplug&) = delete;
  Hotplug& operator=(const Hotplug&) = delete;

  // Every `interval` the device thread probes the board (ID read) while it is attached, or calls
  // `reattach` once it disappeared; a board that comes back replaces the fallback at once and every
  // session gets a `device_back` event. `serving_board` false (`auto` found no board at start):
  // `reattach` is called from the first interval on and its first board replaces the simulator
  // the same way (`device_back` with `first_attach`). Call once, before the network loop runs.
  void enable(BackendFactory reattach, std::chrono::milliseconds interval, bool serving_board);
  // Shutdown: cancels the timer; no probe or attempt starts afterwards (network thread).
  void stop();
  // A USB device of the board(s) arrived or left (libusb notification, any thread): the next probe
  // or re-attach attempt runs now instead of at the end of the interval (counted only when
  // hot-plug is off or stopped).
  void event();
  void set_notifications(bool on) { notifications_ = on; }  // set once at start (network thread)
  // A request or probe met kDeviceGone (device thread): fall back, tell everyone, look for the board.
  void on_device_gone(const Error& e);
  nlohmann::json status_json() const;  // network thread

 private:
  void arm(std::chrono::milliseconds delay);  // network thread
  void step();                                // device thread: one probe or re-attach attempt

  Executor net_, device_;
  DeviceWorker& worker_;
  BackendFactory fallback_;  // builds the simulator when a board disappears (empty: none)
  Hooks hooks_;
  BackendFactory reattach_;  // empty: the backend cannot come back (sim, fake)
  std::chrono::milliseconds interval_{0};
  boost::asio::steady_timer timer_{net_};

  // Network thread.
  bool stopped_ = false;
  std::uint64_t generation_ = 0;  // a timer handler of an older arming does nothing
  bool step_running_ = false;     // a probe/attempt is on the device thread
  bool poke_ = false;             // an event came during that step: re-arm at once
  bool notifications_ = false;
  std::uint64_t events_ = 0;
  bool attached_ = true;              // copy of !lost_ && !awaiting_first_
  bool first_board_pending_ = false;  // copy of awaiting_first_
  std::uint64_t detaches_ = 0, reattaches_ = 0;

  // Device thread.
  bool lost_ = false;            // gone and not yet re-attached
  bool awaiting_first_ = false;  // `auto` on the simulator, no board yet
};

}  // namespace gpubridge::daemon
