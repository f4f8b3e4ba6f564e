// Board hot-plug (issue 4): notice an unplugged board, switch to the fallback (Hub::on_device_gone)
// and pick the board up again when it reappears.
//
// One steady timer on the network executor drives everything; each expiry posts one step to the
// device executor and re-arms only after that step finished, so at most one probe or attempt is
// in flight and the network thread never waits for USB:
// - attached board: a presence probe (ID register read). An unplug is thereby noticed even when no
//   client is sending commands; a probe that finds NO_DEVICE takes the normal device-gone path.
// - after a disappearance: one call of the re-attach factory (libusb/hidapi open + attach, or the
//   emulated stack). On success the board is reset to the defined state and replaces the current
//   backend at once, between two device operations.
//
// Why "at once" even while a client holds the lease: the board lost all device state when it was
// unplugged and the fallback simulator holds state the board never saw, so nothing the holder drew
// survives either way. Waiting for the lease to be released could postpone the board forever. The
// holder keeps its lease and learns from the device_back event ("state": "reset") that it must
// redraw; any other client sees the same event.
#include "gpubridge/common/log.hpp"
#include "gpubridge/daemon/hub.hpp"

namespace gpubridge::daemon {

void Hub::enable_hotplug(BackendFactory reattach, std::chrono::milliseconds interval) {
  reattach_ = std::move(reattach);
  hotplug_interval_ = interval;
  if (!reattach_ || interval.count() <= 0) return;
  boost::asio::post(net_, [this] { arm_hotplug_timer(); });
}

void Hub::stop_hotplug() {
  hotplug_stopped_ = true;
  hotplug_timer_.cancel();
}

void Hub::arm_hotplug_timer() {
  if (hotplug_stopped_) return;
  hotplug_timer_.expires_after(hotplug_interval_);
  hotplug_timer_.async_wait([this](const boost::system::error_code& ec) {
    if (ec || hotplug_stopped_) return;
    boost::asio::post(device_, [this] {
      hotplug_tick();
      boost::asio::post(net_, [this] { arm_hotplug_timer(); });
    });
  });
}

void Hub::install_backend(std::unique_ptr<backends::Backend> backend) {
  if (backend_) backend_->set_scanout_callback({});
  backend_ = std::move(backend);
  backend_->set_scanout_callback([this](std::shared_ptr<const backends::ScanoutFrame> f) { on_scanout(std::move(f)); });
}

void Hub::hotplug_tick() {
  auto log = logger("daemon");
  if (!device_lost_) {
    // Only boards can vanish; "auto" that found no board at start runs the simulator: nothing to probe.
    if (backend_->info().backend != "board") return;
    auto r = backend_->read_register(protocol::index_of(protocol::Reg::ID));
    if (!r && r.error().code == backends::kDeviceGone) on_device_gone(r.error());
    return;
  }
  auto board = reattach_();
  if (!board) {
    log->debug("re-attach: not back yet: {}", board.error().message);
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
  log->info("re-attach: board {} ({}) is back and reset; it replaces the fallback", info.board, info.bridge);
  const nlohmann::json event{{"event", "device_back"},
                             {"backend", info.backend},
                             {"board", info.board},
                             {"bridge", info.bridge},
                             {"state", "reset"},
                             {"message", "board '" + info.board + "' is back: registers, FIFO and memory are in their "
                                         "power-on/reset state; the lease holder keeps the lease and should redraw"}};
  boost::asio::post(net_, [this, info, event] {
    info_ = info;
    ++reattaches_;
    attached_ = true;
    broadcast_event(event);
  });
}

nlohmann::json Hub::hotplug_json() const {
  return {{"enabled", static_cast<bool>(reattach_) && hotplug_interval_.count() > 0},
          {"interval_ms", hotplug_interval_.count()},
          {"attached", attached_},
          {"detaches", detaches_},
          {"reattaches", reattaches_}};
}

}  // namespace gpubridge::daemon
