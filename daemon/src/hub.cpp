#include "gpubridge/daemon/hub.hpp"

#include "gpubridge/common/json_text.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/daemon/session.hpp"
#include "gpubridge/version.hpp"

namespace gpubridge::daemon {

Hub::Hub(Executor net, Executor device, std::unique_ptr<backends::Backend> backend, HubOptions options,
         BackendFactory fallback)
    : net_(net),
      options_(std::move(options)),
      device_(net, device, std::move(backend)),
      info_(device_.backend().info()),
      lease_(
          // Leave the device in a defined state for the next holder: reset, then grant.
          [this](std::function<void()> done) {
            device_.request<void>(
                nullptr, [](backends::Backend& b) { return b.reset(); },
                [done = std::move(done)](Result<void> r) {
                  if (!r && r.error().code != backends::kCancelled)
                    logger("daemon")->warn("device reset before the next lease holder failed: {}", r.error().message);
                  done();
                });
          },
          [this](std::uint32_t id) {
            auto s = find(id);
            if (!s) return false;
            s->on_lease_granted();
            return true;
          }),
      feed_(net, options_.frames_dir, [this](ScanoutFeed::Frame f) { fan_out(std::move(f)); }),
      hotplug_(net, device, device_, std::move(fallback),
               Hotplug::Hooks{[this](const backends::DeviceInfo& info) { info_ = info; },
                              [this](const nlohmann::json& event) { broadcast_event(event); }}) {
  device_.set_scanout_callback([this](std::shared_ptr<const backends::ScanoutFrame> f) { feed_.push(std::move(f)); });
  device_.on_device_gone([this](const Error& e) { hotplug_.on_device_gone(e); });
}

Hub::~Hub() = default;

std::shared_ptr<Session> Hub::find(std::uint32_t id) const {
  auto it = sessions_.find(id);
  return it == sessions_.end() ? nullptr : it->second.lock();
}

std::uint32_t Hub::add_session(const std::shared_ptr<Session>& s) {
  const auto id = next_session_id_++;
  sessions_[id] = s;
  return id;
}

void Hub::remove_session(std::uint32_t id) {
  lease_.release(id);
  sessions_.erase(id);
}

void Hub::make_room_for_handshake(const std::string& transport) {
  std::size_t waiting = 0;
  std::shared_ptr<Session> oldest;
  for (const auto& [id, w] : sessions_) {  // ids grow with time: the first one found is the oldest
    auto s = w.lock();
    if (!s || s->handshaken() || s->closed() || s->transport() != transport) continue;
    if (!oldest) oldest = s;
    ++waiting;
  }
  if (waiting < options_.limits.max_pending_handshakes || !oldest) return;
  log_refusal("closed a " + transport + " connection that sent no HELLO to admit a new one (" +
              std::to_string(waiting) + " were waiting for their handshake, limits.max_pending_handshakes)");
  oldest->fail(protocol::ErrorCode::ServerFull,
               "closed to make room: " + std::to_string(waiting) + " connections were waiting for their HELLO",
               0, /*quiet=*/true);
}

bool Hub::may_handshake(const std::string& transport, std::string& why) const {
  std::size_t all = 0, tcp = 0;
  for (const auto& [id, w] : sessions_) {
    auto s = w.lock();
    if (!s || !s->handshaken() || s->closed()) continue;
    ++all;
    tcp += s->transport() == "tcp";
  }
  const auto cap = options_.limits.max_clients;
  if (all >= cap) {
    why = "server full: " + std::to_string(all) + " clients connected (limits.max_clients); try again later";
    return false;
  }
  // One slot stays for the local Unix socket, so remote peers can never lock out local users.
  if (transport == "tcp" && unix_listening_ && cap >= 2 && tcp >= cap - 1) {
    why = "server full for TCP: " + std::to_string(tcp) + " TCP clients connected and the last of " +
          std::to_string(cap) + " slots (limits.max_clients) is kept for the local Unix socket; try again later";
    return false;
  }
  return true;
}

std::size_t Hub::shutdown_sessions() {
  std::vector<std::shared_ptr<Session>> live;
  for (auto& [id, w] : sessions_)
    if (auto s = w.lock()) live.push_back(std::move(s));
  for (auto& s : live) s->fail(protocol::ErrorCode::ShuttingDown, "gpubridged is shutting down");
  return live.size();
}

void Hub::stop() {
  hotplug_.stop();
  feed_.stop();
  device_.stop();
}

void Hub::enable_hotplug(BackendFactory reattach, std::chrono::milliseconds interval) {
  hotplug_.enable(std::move(reattach), interval, info_.backend == "board");
}

std::string Hub::device_json(const std::string& compression, const std::string& transport) const {
  nlohmann::json j{{"device_kind", protocol::device_kind_info(info_.kind).name},
                   {"backend", info_.backend},     {"board", info_.board},
                   {"bridge", info_.bridge},       {"max_width", info_.max_width},
                   {"max_height", info_.max_height}, {"vram_bytes", info_.vram_bytes},
                   {"id", info_.id},               {"caps", info_.caps},
                   {"caps2", info_.caps2},
                   {"mirror", options_.mirror},    {"accuracy", info_.accuracy},
                   {"daemon_version", kVersion},
                   {"compression", compression},   {"transport", transport}};
  if (!info_.frames_note.empty()) j["frames_note"] = info_.frames_note;
  return json_text(j);
}

namespace {
// STATUS says how each client's bytes travel: "tls", "none (unix socket)", "none (plain TCP)".
std::string encryption_of(const Session& s) {
  switch (s.security()) {
    case Stream::Security::Tls: return "tls";
    case Stream::Security::Plain: return "none (plain TCP)";
    case Stream::Security::Undecided: return "undecided (nothing received yet)";
    case Stream::Security::Local: break;
  }
  return "none (" + s.transport() + " socket)";
}
}  // namespace

nlohmann::json Hub::status_json() const {
  nlohmann::json clients = nlohmann::json::array();
  std::string holder_name;
  for (const auto& [id, w] : sessions_) {
    auto s = w.lock();
    if (!s) continue;
    if (lease_.held_by(id)) holder_name = s->name();
    clients.push_back({{"session", id},
                       {"name", s->name()},
                       {"transport", s->transport()},
                       {"encryption", encryption_of(*s)},
                       {"handshaken", s->handshaken()},
                       {"subscribed", s->subscribed()},
                       {"source", std::string(protocol::to_string(s->frame_source()))},
                       {"lease", lease_.held_by(id)},
                       {"bytes_in", s->bytes_in()}});
  }
  nlohmann::json lease = nullptr;
  if (lease_.holder()) lease = {{"session", lease_.holder()}, {"name", holder_name}};
  const auto uptime = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  const auto or_null = [](const auto& v) { return v ? nlohmann::json(*v) : nlohmann::json(); };
  const MirrorStats m = feed_.mirror_stats();
  const MirrorCounters decorator = mirror_counters();
  const nlohmann::json mirror{{"enabled", options_.mirror},
                              {"compared", m.compared},
                              {"mismatches", m.mismatches},
                              {"first_mismatch", or_null(m.first_mismatch)},
                              {"first_mismatch_pixels", or_null(m.first_mismatch_pixels)},
                              {"last_mismatch", or_null(m.last_mismatch)},
                              {"last_mismatch_pixels", or_null(m.last_mismatch_pixels)},
                              {"model_errors", decorator.model_errors},
                              {"unpaired_frames", decorator.unpaired_frames},
                              {"coalesced_swaps", decorator.coalesced_swaps}};
  nlohmann::json status{{"daemon_version", kVersion},
          {"device_kind", protocol::device_kind_info(info_.kind).name},
          {"backend", info_.backend},
          {"board", info_.board},
          {"bridge", info_.bridge},
          {"accuracy", info_.accuracy},
          {"lease", lease},
          {"lease_waiters", lease_.waiters()},
          {"client_count", clients.size()},
          {"clients", clients},
          {"frames", {{"count", feed_.count()}, {"last_number", feed_.last_number()}, {"pngs_written", feed_.pngs_written()}}},
          {"mirror", mirror},
          {"hotplug", hotplug_.status_json()},
          {"tls", options_.tls_fingerprint.empty() ? nlohmann::json(nullptr)
                                                   : nlohmann::json{{"fingerprint", options_.tls_fingerprint}}},
          {"uptime_s", uptime}};
  if (!info_.frames_note.empty()) status["frames_note"] = info_.frames_note;
  return status;
}

void Hub::fan_out(std::shared_ptr<const backends::ScanoutFrame> frame) {
  auto fanout = std::make_shared<FrameFanout>(std::move(frame));
  // Kept only in mirror mode, where subscribers switch pictures of the same swap.
  if (options_.mirror) newest_fanout_ = fanout;
  for (auto& [id, w] : sessions_)
    if (auto s = w.lock(); s && s->subscribed()) s->offer_frame(fanout);
}

void Hub::offer_newest_frame(Session& s) {
  if (newest_fanout_) s.offer_frame(newest_fanout_);
}

void Hub::broadcast_event(const nlohmann::json& event) {
  // Events use the reply path of each session, so they obey the same byte caps.
  for (auto& [id, w] : sessions_) {
    if (auto s = w.lock(); s && s->handshaken()) s->send_event(json_text(event));
  }
}

}  // namespace gpubridge::daemon
