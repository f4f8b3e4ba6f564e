#pragma once
// Hub: the daemon's shared state, owned by the network thread: sessions, the device lease (one
// holder, FIFO waiters), frame fan-out to subscribers, status. The backend lives on the device
// executor: every backend call goes through device_call(), which runs the work there and posts
// the result back to the network executor, so a slow device never blocks another session's I/O.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>
#include <nlohmann/json.hpp>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/daemon/config.hpp"
#include "gpubridge/daemon/mirror_backend.hpp"
#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::daemon {

class Session;

struct HubOptions {
  Limits limits;
  std::string token;       // required from TCP sessions when non-empty
  std::string frames_dir;  // PNG per scanned-out frame when non-empty
  std::string record_dir;  // binary trace per session when non-empty
  bool mirror = false;     // the backend is a MirrorBackend: frames carry the simulator's reference
};

// Mirror mode bookkeeping (network thread): swaps compared and those whose CRCs differ.
struct MirrorStats {
  std::uint64_t compared = 0, mismatches = 0;
  std::optional<std::uint32_t> first_mismatch, last_mismatch;  // frame numbers
  std::optional<std::uint64_t> first_mismatch_pixels;           // differing pixels; none for CRC-only boards
  std::optional<std::uint64_t> last_mismatch_pixels;            // the same for the latest mismatch
};

// A scanned-out frame encoded once per requested source and format and shared by every subscriber.
class FrameFanout {
 public:
  explicit FrameFanout(std::shared_ptr<const backends::ScanoutFrame> frame) : frame_(std::move(frame)) {}
  // The complete FRAME message for `source` in `format` (encoded on first use); null when this
  // swap has no such picture (a CRC-only board has no board or diff pixels; without mirror mode
  // there is no sim or diff picture).
  std::shared_ptr<const std::vector<std::uint8_t>> message(protocol::FrameSource source, protocol::FrameFormat format);
  std::shared_ptr<const std::vector<std::uint8_t>> message(protocol::FrameFormat format) {
    return message(protocol::FrameSource::Board, format);
  }
  const backends::ScanoutFrame& frame() const { return *frame_; }

 private:
  std::shared_ptr<const backends::ScanoutFrame> picture(protocol::FrameSource source);
  std::shared_ptr<const backends::ScanoutFrame> frame_;
  std::shared_ptr<const backends::ScanoutFrame> diff_;  // computed on first use
  bool diff_done_ = false;
  std::shared_ptr<const std::vector<std::uint8_t>> encoded_[3][4];
};

class Hub {
 public:
  using Executor = boost::asio::any_io_executor;
  // Fallback factory: builds the simulator when a board disappears (empty = no fallback).
  using BackendFactory = std::function<Result<std::unique_ptr<backends::Backend>>()>;

  Hub(Executor net, Executor device, std::unique_ptr<backends::Backend> backend, HubOptions options,
      BackendFactory fallback = {});
  ~Hub();
  Hub(const Hub&) = delete;
  Hub& operator=(const Hub&) = delete;

  const HubOptions& options() const { return options_; }
  Executor net_executor() const { return net_; }

  // --- sessions (network thread) ---
  std::uint32_t add_session(const std::shared_ptr<Session>& s);
  void remove_session(std::uint32_t id);
  std::size_t session_count() const { return sessions_.size(); }
  // Asks every session to close (SHUTTING_DOWN); returns how many were open.
  std::size_t shutdown_sessions();

  // --- lease (network thread) ---
  enum class LeaseResult { Granted, Queued, Busy };
  LeaseResult acquire_lease(std::uint32_t id, protocol::LeaseMode mode);
  // Releases the lease if `id` holds it (the device is reset before the next holder gets it) or
  // removes `id` from the waiters. Returns true if it held the lease.
  bool release_lease(std::uint32_t id);
  bool holds_lease(std::uint32_t id) const { return lease_holder_ == id; }

  // --- device (runs `work(backend)` on the device executor, `done(result)` on the network one) ---
  template <class T, class Work, class Done>
  void device_call(Work work, Done done) {
    boost::asio::post(device_, [this, work = std::move(work), done = std::move(done)]() mutable {
      Result<T> r = work(*backend_);
      if (!r.ok() && r.error().code == backends::kDeviceGone) on_device_gone(r.error());
      boost::asio::post(net_, [r = std::move(r), done = std::move(done)]() mutable { done(std::move(r)); });
    });
  }

  // --- hot-plug (hub_hotplug.cpp; docs/daemon.md "Hot-plug") ---
  // Every `interval` the device thread probes the board (ID read) while it is attached, or calls
  // `reattach` once it disappeared; a board that comes back replaces the fallback at once and
  // every session gets a `device_back` event. When the hub serves a non-board backend at this
  // point (`auto` found no board at start) `reattach` is called from the first interval on, and
  // the first board it returns replaces the simulator the same way (`device_back` with
  // `first_attach`). Call once, before the network loop runs.
  void enable_hotplug(BackendFactory reattach, std::chrono::milliseconds interval);
  // Shutdown: cancels the timer; no probe or attempt starts afterwards (network thread).
  void stop_hotplug();
  // A USB device of the board(s) arrived or left (libusb hot-plug notification, any thread): the
  // next probe or re-attach attempt runs now instead of at the end of the interval. With no
  // enabled hot-plug, or after stop_hotplug(), it is only counted.
  void hotplug_event();
  // Whether such notifications arrive (status reports it); set once at start (network thread).
  void set_hotplug_notifications(bool on) { hotplug_notifications_ = on; }

  std::string device_json() const;     // WELCOME's device description
  nlohmann::json status_json() const;  // STATUS_REPLY
  std::uint64_t frames_seen() const { return frames_seen_; }
  const MirrorStats& mirror_stats() const { return mirror_; }
  // The mirror decorator's own counters (model refusals, unpaired and coalesced swaps), summed over
  // every MirrorBackend this hub served; zero without mirror mode. Any thread.
  MirrorCounters mirror_counters() const;
  // A subscriber switched pictures (SUBSCRIBE with another source): offers it the newest swap
  // again, so a still scene shows the new picture at once (network thread).
  void offer_newest_frame(Session& s);

 private:
  void on_scanout(std::shared_ptr<const backends::ScanoutFrame> frame);  // device thread
  void fan_out(std::shared_ptr<const backends::ScanoutFrame> frame);     // network thread
  void compare_mirrored(const backends::ScanoutFrame& frame);            // network thread
  void on_device_gone(const Error& e);                                   // device thread
  void broadcast_event(const nlohmann::json& event);                     // network thread
  void arm_hotplug_timer(std::chrono::milliseconds delay);               // network thread
  void hotplug_tick();                                                   // device thread
  void install_backend(std::unique_ptr<backends::Backend> backend);      // device thread
  nlohmann::json hotplug_json() const;                                   // network thread
  void grant_next();

  Executor net_, device_;
  std::unique_ptr<backends::Backend> backend_;  // used only on the device executor (see backend_swap_mu_)
  // STATUS (network thread) reads the mirror's counters while the device thread works; the mirror
  // guards them itself. This mutex only keeps backend_ alive and in place meanwhile: the device
  // thread holds it to replace backend_ (hot-plug), the network thread to read the counters.
  mutable std::mutex backend_swap_mu_;
  MirrorCounters retired_mirror_counters_;  // of mirrors replaced by hot-plug; under backend_swap_mu_
  backends::DeviceInfo info_;                   // network-thread copy of backend_->info()
  HubOptions options_;
  BackendFactory fallback_;

  std::map<std::uint32_t, std::weak_ptr<Session>> sessions_;
  std::uint32_t next_session_id_ = 1;
  std::uint32_t lease_holder_ = 0;  // 0 = free
  std::deque<std::uint32_t> lease_waiters_;
  bool resetting_ = false;          // a released lease is being reset; grant after it finishes
  std::uint64_t frames_seen_ = 0;
  std::uint32_t last_frame_number_ = 0;
  MirrorStats mirror_;
  std::shared_ptr<FrameFanout> newest_fanout_;  // the last swap, for offer_newest_frame
  std::atomic<std::uint64_t> frame_pngs_written_{0};  // incremented on the device thread
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();

  // Hot-plug (hub_hotplug.cpp).
  BackendFactory reattach_;                     // empty: the backend cannot come back (sim, fake)
  std::chrono::milliseconds hotplug_interval_{0};
  boost::asio::steady_timer hotplug_timer_{net_};
  bool hotplug_stopped_ = false;                // network thread
  std::uint64_t hotplug_timer_generation_ = 0;  // network thread: a timer handler of an older arming does nothing
  bool hotplug_step_running_ = false;           // network thread: a probe/attempt is on the device thread
  bool hotplug_poke_ = false;                   // network thread: an event came during that step
  bool hotplug_notifications_ = false;          // network thread
  std::uint64_t hotplug_events_ = 0;            // network thread
  bool device_lost_ = false;                    // device thread: gone and not yet re-attached
  bool awaiting_first_board_ = false;           // device thread: `auto` on the simulator, no board yet
  bool attached_ = true;                        // network-thread copy of !device_lost_ && !awaiting_first_board_
  bool first_board_pending_ = false;            // network-thread copy of awaiting_first_board_
  std::uint64_t detaches_ = 0, reattaches_ = 0;  // network thread
};

}  // namespace gpubridge::daemon
