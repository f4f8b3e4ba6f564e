#pragma once
// Hub: what the sessions share, owned by the network thread: the session registry and the
// connection budget, the lease, the device (DeviceWorker: the backend on its own thread), the
// swaps fanned out to subscribers (ScanoutFeed), hot-plug, status and events. Like the connection
// manager of the Asio/Beast examples; the per-connection work is in Session and RequestHandler.
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>
#include <nlohmann/json.hpp>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/daemon/config.hpp"
#include "gpubridge/daemon/device_worker.hpp"
#include "gpubridge/daemon/frame_fanout.hpp"
#include "gpubridge/daemon/hotplug.hpp"
#include "gpubridge/daemon/lease.hpp"
#include "gpubridge/daemon/log_limiter.hpp"
#include "gpubridge/daemon/scanout_feed.hpp"

namespace gpubridge::daemon {

class Session;

struct HubOptions {
  Limits limits;
  std::string token;       // required from TCP sessions when non-empty
  std::string frames_dir;  // PNG per scanned-out frame when non-empty
  std::string record_dir;  // binary trace per session when non-empty
  bool mirror = false;     // the backend is a MirrorBackend: frames carry the simulator's reference
  std::string tls_fingerprint;  // the certificate clients pin, when TCP listeners speak TLS
};

class Hub {
 public:
  using Executor = boost::asio::any_io_executor;
  using BackendFactory = daemon::BackendFactory;  // builds a backend (fallback simulator, re-attach)

  Hub(Executor net, Executor device, std::unique_ptr<backends::Backend> backend, HubOptions options,
      BackendFactory fallback = {});
  ~Hub();
  Hub(const Hub&) = delete;
  Hub& operator=(const Hub&) = delete;

  const HubOptions& options() const { return options_; }
  Executor net_executor() const { return net_; }

  // --- sessions and the connection budget (network thread; docs/daemon.md "Limits") ---
  std::uint32_t add_session(const std::shared_ptr<Session>& s);
  void remove_session(std::uint32_t id);
  std::size_t session_count() const { return sessions_.size(); }
  // A new connection over `transport` is about to be admitted: when max_pending_handshakes
  // sessions of that transport are still waiting for their HELLO, the oldest of them is closed.
  void make_room_for_handshake(const std::string& transport);
  // Whether a session over `transport` may complete its HELLO: at most max_clients handshaken
  // sessions, of which TCP may take all but one while the daemon also listens on a Unix socket.
  // On false, `why` is the text of the SERVER_FULL refusal.
  bool may_handshake(const std::string& transport, std::string& why) const;
  void set_unix_listening(bool on) { unix_listening_ = on; }
  // Counts a refused or evicted connection and logs at most one line per second about them (warn).
  void log_refusal(const std::string& what) { refusals_.note(what); }
  // The same for sessions closed for a protocol error or a timeout (info): a flood of bad clients
  // costs a line per second, not a line each.
  void log_closing(const std::string& what) { closings_.note(what); }
  // Asks every session to close (SHUTTING_DOWN); returns how many were open.
  std::size_t shutdown_sessions();
  // Shutdown of everything but the sessions: no hot-plug step, no new device work (the running
  // request stops at its next cancel point), no more frames (any thread but the device's).
  void stop();

  // --- the lease and the device ---
  Lease& lease() { return lease_; }
  DeviceWorker& device() { return device_; }
  const backends::DeviceInfo& device_info() const { return info_; }  // network-thread copy

  // --- hot-plug (docs/daemon.md "Hot-plug"; Hotplug::enable etc.) ---
  void enable_hotplug(BackendFactory reattach, std::chrono::milliseconds interval);
  void stop_hotplug() { hotplug_.stop(); }
  void hotplug_event() { hotplug_.event(); }
  void set_hotplug_notifications(bool on) { hotplug_.set_notifications(on); }

  // WELCOME's device description, with the session's compression ("zstd" | "none") and transport.
  std::string device_json(const std::string& compression = "none", const std::string& transport = "unix") const;
  nlohmann::json status_json() const;  // STATUS_REPLY
  std::uint64_t frames_seen() const { return feed_.count(); }
  MirrorStats mirror_stats() const { return feed_.mirror_stats(); }
  // The mirror decorator's own counters (model refusals, unpaired and coalesced swaps), summed over
  // every MirrorBackend this hub served; zero without mirror mode. Any thread.
  MirrorCounters mirror_counters() const { return device_.mirror_counters(); }
  // A subscriber switched pictures (SUBSCRIBE with another source): offers it the newest swap
  // again, so a still scene shows the new picture at once (network thread).
  void offer_newest_frame(Session& s);

 private:
  void fan_out(std::shared_ptr<const backends::ScanoutFrame> frame);  // network thread
  void broadcast_event(const nlohmann::json& event);                 // network thread
  std::shared_ptr<Session> find(std::uint32_t id) const;

  Executor net_;
  HubOptions options_;
  DeviceWorker device_;
  backends::DeviceInfo info_;  // network-thread copy of the backend's info()
  Lease lease_;
  ScanoutFeed feed_;
  Hotplug hotplug_;
  std::shared_ptr<FrameFanout> newest_fanout_;  // mirror mode: the last swap, for offer_newest_frame

  std::map<std::uint32_t, std::weak_ptr<Session>> sessions_;
  std::uint32_t next_session_id_ = 1;
  bool unix_listening_ = false;
  LogLimiter refusals_{spdlog::level::warn};
  LogLimiter closings_{spdlog::level::info};
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
};

}  // namespace gpubridge::daemon
