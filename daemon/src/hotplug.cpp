// Board hot-plug (issue 4): notice an unplugged board, switch to the fallback (on_device_gone) and
// pick the board up again when it reappears.
//
// One steady timer on the network executor drives everything; each expiry posts one step to the
// device executor and re-arms only after that step finished, so at most one probe or attempt is
// in flight and the network thread never waits for USB. A libusb hot-plug notification
// (event()) re-arms the timer to expire at once, or, while a step runs, makes that step
// re-arm it at once, so an event is never lost and never starts a second step:
// - attached board: a presence probe (ID register read). An unplug is thereby noticed even when no
//   client is sending commands; a probe that finds NO_DEVICE takes the normal device-gone path.
// - after a disappearance: one call of the re-attach factory (libusb/hidapi open + attach, or the
//   emulated stack). On success the board is reset to the defined state and replaces the current
//   backend at once, between two device operations.
// - `auto` that found no board at start (it runs the simulator): the same factory call, so a board
//   plugged in after the daemon started replaces the simulator exactly as a board coming back does.
//
// Why "at once" even while a client holds the lease: the board lost all device state when it was
// unplugged and the fallback simulator holds state the board never saw, so nothing the holder drew
// survives either way. Waiting for the lease to be released could postpone the board forever. The
// holder keeps its lease and learns from the device_back event ("state": "reset") that it must
// redraw; any other client sees the same event.
#include "gpubridge/daemon/hotplug.hpp"

#include <utility>

#include "gpubridge/common/log.hpp"

namespace gpubridge::daemon {

Hotplug::Hotplug(Executor net, Executor device, DeviceWorker& worker, BackendFactory fallback, Hooks hooks)
    : net_(std::move(net)), device_(std::move(device)), worker_(worker), fallback_(std::move(fallback)),
      hooks_(std::move(hooks)) {}

void Hotplug::enable(BackendFactory reattach, std::chrono::milliseconds interval, bool serving_board) {
  reattach_ = std::move(reattach);
  interval_ = interval;
  if (!reattach_ || interval.count() <= 0) return;
  // A re-attach factory exists only for board configurations; serving anything but a board now
  // means `auto` found none at start and fell back to the simulator. Set before the loops run,
  // so the device thread sees it through the post below.
  awaiting_first_ = !serving_board;
  first_board_pending_ = awaiting_first_;
  attached_ = !awaiting_first_;
  boost::asio::post(net_, [this] { arm(interval_); });
}

void Hotplug::stop() {
  stopped_ = true;
  timer_.cancel();
}

void Hotplug::arm(std::chrono::milliseconds delay) {
  if (stopped_) return;
  // Re-arming cancels the pending wait, but its handler may already be queued with success: the
  // generation tells it that it was superseded.
  const std::uint64_t generation = ++generation_;
  timer_.expires_after(delay);
  timer_.async_wait([this, generation](const boost::system::error_code& ec) {
    if (ec || stopped_ || generation != generation_) return;
    step_running_ = true;
    boost::asio::post(device_, [this] {
      if (!worker_.stopping()) step();
      boost::asio::post(net_, [this] {
        step_running_ = false;
        arm(std::exchange(poke_, false) ? std::chrono::milliseconds(0) : interval_);
      });
    });
  });
}

void Hotplug::event() {
  boost::asio::post(net_, [this] {
    ++events_;
    if (stopped_ || !reattach_ || interval_.count() <= 0) return;
    if (step_running_)
      poke_ = true;  // that step re-arms at once when it is done
    else
      arm(std::chrono::milliseconds(0));
  });
}

void Hotplug::on_device_gone(const Error& e) {
  // Reported once per disappearance: without a fallback the dead board stays in place and every
  // later command fails with DEVICE_GONE too (each caller gets that in its error reply).
  if (lost_) return;
  lost_ = true;
  logger("daemon")->error("device gone: {}", e.message);
  nlohmann::json event{{"event", "device_gone"}, {"message", e.message}};
  if (fallback_) {
    if (auto sim = fallback_(); sim) {
      worker_.install(std::move(*sim));
      const auto info = worker_.backend().info();
      event["fallback"] = info.backend;
      boost::asio::post(net_, [this, info] { hooks_.backend_changed(info); });
    }
  }
  if (reattach_ && interval_.count() > 0) event["reattach_interval_ms"] = interval_.count();
  boost::asio::post(net_, [this, event] {
    ++detaches_;
    attached_ = false;
    hooks_.broadcast(event);
  });
}

void Hotplug::step() {
  auto log = logger("daemon");
  if (!lost_ && !awaiting_first_) {
    // Only boards can vanish (a fallback simulator is only ever in place while lost_).
    auto& backend = worker_.backend();
    if (backend.info().backend != "board") return;
    auto r = backend.read_register(protocol::index_of(protocol::Reg::ID));
    if (!r && r.error().code == backends::kDeviceGone) on_device_gone(r.error());
    return;
  }
  const bool first = awaiting_first_;
  auto board = reattach_();
  if (!board) {
    log->debug("{}: {}", first ? "auto: still no board" : "re-attach: not back yet", board.error().message);
    return;
  }
  // attach() checked ID/CAPS and wrote HOST_TAG; RESET puts registers, FIFO and flags into their
  // reset values, the same defined state a new lease holder gets.
  if (auto r = (*board)->reset(); !r) {
    log->warn("re-attach: the board opened but its reset failed (will retry): {}", r.error().message);
    return;
  }
  const auto info = (*board)->info();
  worker_.install(std::move(*board));
  lost_ = false;
  awaiting_first_ = false;
  if (first)
    log->info("auto: board {} ({}) plugged in; reset, it replaces the simulator", info.board, info.bridge);
  else
    log->info("re-attach: board {} ({}) is back and reset; it replaces the fallback", info.board, info.bridge);
  // A first board uses the same event as a returning one: for every client the consequence is the
  // same (another device in its reset state serves from now on; redraw), and clients that already
  // redraw on device_back need no change. `first_attach` tells the two apart.
  const std::string what = first ? "board '" + info.board + "' was plugged in and replaces the simulator"
                                 : "board '" + info.board + "' is back";
  const nlohmann::json event{{"event", "device_back"},
                             {"backend", info.backend},
                             {"board", info.board},
                             {"bridge", info.bridge},
                             {"state", "reset"},
                             {"first_attach", first},
                             {"message", what + ": registers, FIFO and memory are in their power-on/reset state; "
                                                "the lease holder keeps the lease and should redraw"}};
  boost::asio::post(net_, [this, info, event, first] {
    hooks_.backend_changed(info);
    if (first) first_board_pending_ = false;
    else ++reattaches_;
    attached_ = true;
    hooks_.broadcast(event);
  });
}

nlohmann::json Hotplug::status_json() const {
  return {{"enabled", static_cast<bool>(reattach_) && interval_.count() > 0},
          {"interval_ms", interval_.count()},
          {"attached", attached_},
          // `auto` started on the simulator and no board was plugged in yet (attached is false, but
          // nothing was ever detached).
          {"awaiting_first_board", first_board_pending_},
          {"detaches", detaches_},
          {"reattaches", reattaches_},
          // libusb hot-plug notifications: whether they arrive, and how many did (plugs and unplugs
          // of the boards' USB ids, whether or not they changed anything).
          {"usb_notifications", notifications_},
          {"usb_events", events_}};
}

}  // namespace gpubridge::daemon
