#include "gpubridge/daemon/hub.hpp"

#include <cstdio>
#include <filesystem>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/daemon/frame_diff.hpp"
#include "gpubridge/daemon/session.hpp"
#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/version.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::daemon {
namespace {

using protocol::FrameFormat;
using protocol::PixelFormat;

std::optional<PixelFormat> pixel_format_for(FrameFormat f, PixelFormat native) {
  switch (f) {
    case FrameFormat::Native: return native;
    case FrameFormat::RGBA8888: return PixelFormat::RGBA8888;
    case FrameFormat::RGB565: return PixelFormat::RGB565;
    case FrameFormat::RGBA2222: return PixelFormat::RGBA2222;
  }
  return std::nullopt;
}

}  // namespace

std::shared_ptr<const backends::ScanoutFrame> FrameFanout::picture(protocol::FrameSource source) {
  switch (source) {
    case protocol::FrameSource::Board: return frame_->pixels.empty() ? nullptr : frame_;
    case protocol::FrameSource::Sim:
      return frame_->reference && !frame_->reference->pixels.empty() ? frame_->reference : nullptr;
    case protocol::FrameSource::Diff:
      if (!diff_done_ && frame_->reference) diff_ = diff_frame(*frame_, *frame_->reference);
      diff_done_ = true;
      return diff_;
  }
  return nullptr;
}

std::shared_ptr<const std::vector<std::uint8_t>> FrameFanout::message(protocol::FrameSource source, FrameFormat format) {
  const auto src = static_cast<std::size_t>(source);
  const auto slot = static_cast<std::size_t>(format) & 3;
  if (src >= 3) return nullptr;
  if (encoded_[src][slot]) return encoded_[src][slot];
  const auto shown = picture(source);
  if (!shown) return nullptr;
  const auto& f = *shown;
  const PixelFormat target = pixel_format_for(format, f.format).value_or(f.format);
  std::vector<std::uint8_t> converted;
  std::span<const std::uint8_t> pixels = f.pixels;
  if (target != f.format) {
    converted = device_from_image(target, image_from_device(f.format, f.width, f.height, f.pixels));
    pixels = converted;
  }
  protocol::FrameData d;
  d.number = frame_->number;  // every picture of a swap carries the board's frame number and swap time
  d.width = static_cast<std::uint16_t>(f.width);
  d.height = static_cast<std::uint16_t>(f.height);
  d.format = target;
  d.crc = target == f.format ? f.crc : protocol::crc32(pixels);
  d.swap_ns = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(frame_->swap_time.time_since_epoch()).count());
  d.pixels = pixels;
  d.source = source;
  auto bytes = std::make_shared<std::vector<std::uint8_t>>();
  protocol::encode(protocol::Message{0, d}, *bytes);
  encoded_[src][slot] = std::move(bytes);
  return encoded_[src][slot];
}

Hub::Hub(Executor net, Executor device, std::unique_ptr<backends::Backend> backend, HubOptions options,
         BackendFactory fallback)
    : net_(std::move(net)),
      device_(std::move(device)),
      backend_(std::move(backend)),
      info_(backend_->info()),
      options_(std::move(options)),
      fallback_(std::move(fallback)) {
  backend_->set_scanout_callback([this](std::shared_ptr<const backends::ScanoutFrame> f) { on_scanout(std::move(f)); });
}

Hub::~Hub() {
  if (backend_) backend_->set_scanout_callback({});
}

std::uint32_t Hub::add_session(const std::shared_ptr<Session>& s) {
  const auto id = next_session_id_++;
  sessions_[id] = s;
  return id;
}

void Hub::remove_session(std::uint32_t id) {
  release_lease(id);
  sessions_.erase(id);
}

std::size_t Hub::shutdown_sessions() {
  std::vector<std::shared_ptr<Session>> live;
  for (auto& [id, w] : sessions_)
    if (auto s = w.lock()) live.push_back(std::move(s));
  for (auto& s : live) s->fail(protocol::ErrorCode::ShuttingDown, "gpubridged is shutting down");
  return live.size();
}

Hub::LeaseResult Hub::acquire_lease(std::uint32_t id, protocol::LeaseMode mode) {
  if (lease_holder_ == id) return LeaseResult::Granted;
  if (lease_holder_ == 0 && !resetting_ && lease_waiters_.empty()) {
    lease_holder_ = id;
    return LeaseResult::Granted;
  }
  if (mode == protocol::LeaseMode::FailIfBusy) return LeaseResult::Busy;
  lease_waiters_.push_back(id);
  return LeaseResult::Queued;
}

bool Hub::release_lease(std::uint32_t id) {
  std::erase(lease_waiters_, id);
  if (lease_holder_ != id || id == 0) return false;
  lease_holder_ = 0;
  // Leave the device in a defined state for the next holder: reset, then grant.
  resetting_ = true;
  device_call<void>([](backends::Backend& b) { return b.reset(); },
                    [this](Result<void> r) {
                      if (!r) logger("daemon")->warn("device reset after lease release failed: {}", r.error().message);
                      resetting_ = false;
                      grant_next();
                    });
  return true;
}

void Hub::grant_next() {
  while (lease_holder_ == 0 && !resetting_ && !lease_waiters_.empty()) {
    const auto id = lease_waiters_.front();
    lease_waiters_.pop_front();
    auto it = sessions_.find(id);
    if (it == sessions_.end()) continue;
    auto s = it->second.lock();
    if (!s) continue;
    lease_holder_ = id;
    s->on_lease_granted();
  }
}

std::string Hub::device_json() const {
  nlohmann::json j{{"backend", info_.backend},     {"board", info_.board},
                   {"bridge", info_.bridge},       {"max_width", info_.max_width},
                   {"max_height", info_.max_height}, {"vram_bytes", info_.vram_bytes},
                   {"id", info_.id},               {"caps", info_.caps},
                   {"mirror", options_.mirror},    {"daemon_version", kVersion}};
  return json_text(j);
}

nlohmann::json Hub::status_json() const {
  nlohmann::json clients = nlohmann::json::array();
  std::string holder_name;
  for (const auto& [id, w] : sessions_) {
    auto s = w.lock();
    if (!s) continue;
    if (id == lease_holder_) holder_name = s->name();
    clients.push_back({{"session", id},
                       {"name", s->name()},
                       {"transport", s->transport()},
                       {"handshaken", s->handshaken()},
                       {"subscribed", s->subscribed()},
                       {"source", std::string(protocol::to_string(s->frame_source()))},
                       {"lease", id == lease_holder_},
                       {"bytes_in", s->bytes_in()}});
  }
  nlohmann::json lease = nullptr;
  if (lease_holder_) lease = {{"session", lease_holder_}, {"name", holder_name}};
  const auto uptime = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  const auto frame_or_null = [](const std::optional<std::uint32_t>& n) { return n ? nlohmann::json(*n) : nlohmann::json(); };
  const MirrorCounters decorator = mirror_counters();
  const nlohmann::json mirror{{"enabled", options_.mirror},
                              {"compared", mirror_.compared},
                              {"mismatches", mirror_.mismatches},
                              {"first_mismatch", frame_or_null(mirror_.first_mismatch)},
                              {"first_mismatch_pixels", mirror_.first_mismatch_pixels
                                                            ? nlohmann::json(*mirror_.first_mismatch_pixels)
                                                            : nlohmann::json()},
                              {"last_mismatch", frame_or_null(mirror_.last_mismatch)},
                              {"last_mismatch_pixels", mirror_.last_mismatch_pixels
                                                           ? nlohmann::json(*mirror_.last_mismatch_pixels)
                                                           : nlohmann::json()},
                              {"model_errors", decorator.model_errors},
                              {"unpaired_frames", decorator.unpaired_frames},
                              {"coalesced_swaps", decorator.coalesced_swaps}};
  return {{"daemon_version", kVersion},
          {"backend", info_.backend},
          {"board", info_.board},
          {"bridge", info_.bridge},
          {"lease", lease},
          {"lease_waiters", lease_waiters_.size()},
          {"client_count", clients.size()},
          {"clients", clients},
          {"frames", {{"count", frames_seen_}, {"last_number", last_frame_number_},
                      {"pngs_written", frame_pngs_written_.load()}}},
          {"mirror", mirror},
          {"hotplug", hotplug_json()},
          {"uptime_s", uptime}};
}

MirrorCounters Hub::mirror_counters() const {
  std::lock_guard lock(backend_swap_mu_);
  MirrorCounters total = retired_mirror_counters_;
  if (const auto* mirror = dynamic_cast<const MirrorBackend*>(backend_.get())) total += mirror->counters();
  return total;
}

void Hub::on_scanout(std::shared_ptr<const backends::ScanoutFrame> frame) {
  // A board whose profile says `"scanout": "crc"` reports the swap and its FRAME_CRC but no pixels:
  // count it, but never turn it into a blank PNG or a blank frame for subscribers.
  const bool has_pixels = !frame->pixels.empty();
  if (has_pixels && !options_.frames_dir.empty()) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06u.png", frame->number);
    const auto path = std::filesystem::path(options_.frames_dir) / name;
    if (auto r = save_png(path, image_from_device(frame->format, frame->width, frame->height, frame->pixels)); !r)
      logger("daemon")->warn("frames dir: {}", r.error().message);
    else
      frame_pngs_written_.fetch_add(1, std::memory_order_relaxed);
  }
  boost::asio::post(net_, [this, frame = std::move(frame)]() mutable { fan_out(std::move(frame)); });
}

void Hub::fan_out(std::shared_ptr<const backends::ScanoutFrame> frame) {
  ++frames_seen_;
  last_frame_number_ = frame->number;
  if (frame->reference) compare_mirrored(*frame);
  // CRC-only scanout has no board picture (see on_scanout); in mirror mode the simulator's
  // picture still goes to its subscribers, so the fan-out decides per subscriber (null = none).
  if (frame->pixels.empty() && !frame->reference) return;
  auto fanout = std::make_shared<FrameFanout>(std::move(frame));
  // Kept only in mirror mode, where subscribers switch pictures of the same swap.
  if (options_.mirror) newest_fanout_ = fanout;
  for (auto& [id, w] : sessions_)
    if (auto s = w.lock(); s && s->subscribed()) s->offer_frame(*fanout);
}

void Hub::offer_newest_frame(Session& s) {
  if (newest_fanout_) s.offer_frame(*newest_fanout_);
}

void Hub::compare_mirrored(const backends::ScanoutFrame& frame) {
  // FRAME_CRC is the device's own CRC of the scanned-out bytes, so CRC-only boards compare too.
  ++mirror_.compared;
  if (frame.crc == frame.reference->crc) return;
  ++mirror_.mismatches;
  mirror_.last_mismatch = frame.number;
  // Counting the differing pixels of every mismatch (not only the first) shows whether a fault
  // grows or stays put; it costs one pass over the frame, and only when the CRCs differ.
  std::optional<std::uint64_t> pixels;
  if (!frame.pixels.empty()) {
    std::uint64_t differing = 0;
    if (diff_frame(frame, *frame.reference, &differing)) pixels = differing;
  }
  mirror_.last_mismatch_pixels = pixels;
  if (mirror_.first_mismatch) return;
  mirror_.first_mismatch = frame.number;
  mirror_.first_mismatch_pixels = pixels;
  const std::string where = pixels ? ", " + std::to_string(*pixels) + " pixels differ" : "";
  logger("daemon")->warn("mirror: frame {} differs from the simulator (board CRC 0x{:08X}, simulator CRC 0x{:08X}{}); "
                         "first mismatch, later ones are counted in status (mirror.mismatches)",
                         frame.number, frame.crc, frame.reference->crc, where);
}

void Hub::on_device_gone(const Error& e) {
  // Reported once per disappearance: without a fallback the dead board stays in place and every
  // later command fails with DEVICE_GONE too (each caller gets that in its error reply).
  if (device_lost_) return;
  device_lost_ = true;
  logger("daemon")->error("device gone: {}", e.message);
  nlohmann::json event{{"event", "device_gone"}, {"message", e.message}};
  if (fallback_) {
    if (auto sim = fallback_(); sim) {
      install_backend(std::move(*sim));
      event["fallback"] = backend_->info().backend;
      auto info = backend_->info();
      boost::asio::post(net_, [this, info] { info_ = info; });
    }
  }
  if (reattach_ && hotplug_interval_.count() > 0) event["reattach_interval_ms"] = hotplug_interval_.count();
  boost::asio::post(net_, [this, event] {
    ++detaches_;
    attached_ = false;
    broadcast_event(event);
  });
}

void Hub::broadcast_event(const nlohmann::json& event) {
  // Events use the reply path of each session, so they obey the same byte caps.
  for (auto& [id, w] : sessions_) {
    if (auto s = w.lock(); s && s->handshaken()) s->send_event(json_text(event));
  }
}

}  // namespace gpubridge::daemon
