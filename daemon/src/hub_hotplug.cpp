// Board hot-plug (issue 4): notice an unplugged board, switch to the fallback (Hub::on_device_gone)
// and pick the board up again when it reappears.
//
// One steady timer on the network executor drives everything; each expiry posts one step to the
// device executor and re-arms only after that step finished, so at most one probe or attempt is
// in flight and the network thread never waits for USB. A libusb hot-plug notification
// (hotplug_event) re-arms the timer to expire at once, or, while a step runs, makes that step
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
#include <utility>

#include "gpubridge/common/log.hpp"
#include "gpubridge/daemon/hub.hpp"

namespace gpubridge::daemon {

void Hub::enable_hotplug(BackendFactory reattach, std::chrono::milliseconds interval) {
  reattach_ = std::move(reattach);
  hotplug_interval_ = interval;
  if (!reattach_ || interval.count() <= 0) return;
  // A re-attach factory exists only for board configurations; serving anything but a board now
  // means `auto` found none at start and fell back to the simulator. Set before the loops run,
  // so the device thread sees it through the post below.
  awaiting_first_board_ = info_.backend != "board";
  first_board_pending_ = awaiting_first_board_;
  attached_ = !awaiting_first_board_;
  boost::asio::post(net_, [this] { arm_hotplug_timer(hotplug_interval_); });
}

void Hub::stop_hotplug() {
  hotplug_stopped_ = true;
  hotplug_timer_.cancel();
}

void Hub::arm_hotplug_timer(std::chrono::milliseconds delay) {
  if (hotplug_stopped_) return;
  // Re-arming cancels the pending wait, but its handler may already be queued with success: the
  // generation tells it that it was superseded.
  const std::uint64_t generation = ++hotplug_timer_generation_;
  hotplug_timer_.expires_after(delay);
  hotplug_timer_.async_wait([this, generation](const boost::system::error_code& ec) {
    if (ec || hotplug_stopped_ || generation != hotplug_timer_generation_) return;
    hotplug_step_running_ = true;
    boost::asio::post(device_, [this] {
      hotplug_tick();
      boost::asio::post(net_, [this] {
        hotplug_step_running_ = false;
        arm_hotplug_timer(std::exchange(hotplug_poke_, false) ? std::chrono::milliseconds(0) : hotplug_interval_);
      });
    });
  });
}

void Hub::hotplug_event() {
  boost::asio::post(net_, [this] {
    ++hotplug_events_;
    if (hotplug_stopped_ || !reattach_ || hotplug_interval_.count() <= 0) return;
    if (hotplug_step_running_)
      hotplug_poke_ = true;  // that step re-arms at once when it is done
    else
      arm_hotplug_timer(std::chrono::milliseconds(0));
  });
}

void Hub::install_backend(std::unique_ptr<backends::Backend> backend) {
  if (backend_) backend_->set_scanout_callback({});
  std::unique_ptr<backends::Backend> old;
  {
    // STATUS reads the mirror's counters from the network thread: swap under the lock and keep
    // what the outgoing mirror counted, so the totals survive an unplug.
    std::lock_guard lock(backend_swap_mu_);
    if (const auto* mirror = dynamic_cast<const MirrorBackend*>(backend_.get()))
      retired_mirror_counters_ += mirror->counters();
    old = std::exchange(backend_, std::move(backend));
  }
  old.reset();  // closing a board may take a while: outside the lock
  backend_->set_scanout_callback([this](std::shared_ptr<const backends::ScanoutFrame> f) { on_scanout(std::move(f)); });
}

void Hub::hotplug_tick() {
  auto log = logger("daemon");
  if (!device_lost_ && !awaiting_first_board_) {
    // Only boards can vanish (a fallback simulator is only ever in place while device_lost_).
    if (backend_->info().backend != "board") return;
    auto r = backend_->read_register(protocol::index_of(protocol::Reg::ID));
    if (!r && r.error().code == backends::kDeviceGone) on_device_gone(r.error());
    return;
  }
  const bool first = awaiting_first_board_;
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
  install_backend(std::move(*board));
  device_lost_ = false;
  awaiting_first_board_ = false;
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
    info_ = info;
    if (first) first_board_pending_ = false;
    else ++reattaches_;
    attached_ = true;
    broadcast_event(event);
  });
}

nlohmann::json Hub::hotplug_json() const {
  return {{"enabled", static_cast<bool>(reattach_) && hotplug_interval_.count() > 0},
          {"interval_ms", hotplug_interval_.count()},
          {"attached", attached_},
          // `auto` started on the simulator and no board was plugged in yet (attached is false, but
          // nothing was ever detached).
          {"awaiting_first_board", first_board_pending_},
          {"detaches", detaches_},
          {"reattaches", reattaches_},
          // libusb hot-plug notifications: whether they arrive, and how many did (plugs and unplugs
          // of the boards' USB ids, whether or not they changed anything).
          {"usb_notifications", hotplug_notifications_},
          {"usb_events", hotplug_events_}};
}

}  // namespace gpubridge::daemon
