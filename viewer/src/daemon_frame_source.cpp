#include "gpubridge/viewer/daemon_frame_source.hpp"

#include <nlohmann/json.hpp>

#include "gpubridge/client/address.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/common/log.hpp"

namespace gpubridge::viewer {
namespace {

using namespace std::chrono_literals;
constexpr auto kConnectTimeout = 2000ms;
constexpr auto kHandshakeTimeout = 5000ms;
constexpr auto kRetryDelay = 500ms;
constexpr auto kPollInterval = 200ms;  // how often the reader checks for stop
constexpr auto kMirrorStatusInterval = 500ms;  // mismatch count refresh in mirror mode

Frame to_viewer_frame(client::ReceivedFrame&& f) {
  Frame out;
  out.number = f.number;
  out.width = f.width;
  out.height = f.height;
  out.format = f.format;
  out.crc = f.crc;
  out.swap_ns = f.swap_ns;
  out.pixels = std::move(f.pixels);
  out.source = f.source;
  return out;
}

bool is_auth_failure(const Error& e) { return client::is_protocol_error(e, protocol::ErrorCode::AuthFailed); }

}  // namespace

std::pair<std::string, std::string> backend_and_board(const std::string& device_json) {
  const auto j = nlohmann::json::parse(device_json, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return {"?", ""};
  const auto text = [&](const char* key) {
    const auto it = j.find(key);
    return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
  };
  return {text("backend"), text("board")};
}

bool mirror_enabled(const std::string& device_json) {
  const auto j = nlohmann::json::parse(device_json, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return false;
  const auto it = j.find("mirror");
  return it != j.end() && it->is_boolean() && it->get<bool>();
}

namespace {
std::string device_text(const std::string& device_json, const char* key) {
  const auto j = nlohmann::json::parse(device_json, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return {};
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}
}  // namespace

std::string frames_note(const std::string& device_json) { return device_text(device_json, "frames_note"); }

std::string device_accuracy(const std::string& device_json) { return device_text(device_json, "accuracy"); }

std::optional<std::pair<std::uint64_t, std::uint64_t>> mirror_counts(const std::string& status_json) {
  const auto j = nlohmann::json::parse(status_json, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return std::nullopt;
  const auto m = j.find("mirror");
  if (m == j.end() || !m->is_object()) return std::nullopt;
  const auto compared = m->find("compared"), mismatches = m->find("mismatches");
  if (compared == m->end() || mismatches == m->end() || !compared->is_number_unsigned() ||
      !mismatches->is_number_unsigned())
    return std::nullopt;
  return std::pair{compared->get<std::uint64_t>(), mismatches->get<std::uint64_t>()};
}

DaemonFrameSource::DaemonFrameSource(DaemonSourceConfig config) : config_(std::move(config)) {
  auto parsed = client::parse_connect_address(config_.address);
  display_address_ = parsed ? parsed->to_string() : config_.address;
}

void DaemonFrameSource::run(std::stop_token stop) {
  auto log = logger("viewer");
  SourceStatus status;
  status.address = display_address_;
  status.state = SourceStatus::State::Connecting;
  publish_status(status);
  const auto fail = [&](std::string message) {
    status.state = SourceStatus::State::Failed;
    status.message = std::move(message);
    publish_status(status);
  };
  if (auto parsed = client::parse_connect_address(config_.address); !parsed) {
    fail(parsed.error().message);
    return;
  }

  bool ever_connected = false;
  protocol::FrameSource picture = config_.picture;  // kept across reconnects
  status.picture = picture;
  while (!stop.stop_requested()) {
    auto connection = client::Client::connect(config_.address, kConnectTimeout);
    if (!connection) {
      if (!ever_connected && !config_.wait_at_start) {
        fail(connection.error().message + " (--wait keeps trying)");
        return;
      }
      if (status.state != SourceStatus::State::Waiting || status.message != connection.error().message) {
        status.state = SourceStatus::State::Waiting;
        status.message = connection.error().message;
        publish_status(status);
      }
      if (!sleep_for(stop, kRetryDelay)) return;
      continue;
    }
    client::Client& c = *connection;
    auto session = c.handshake("gpubridge-view", config_.token, kHandshakeTimeout);
    if (!session) {
      if (is_auth_failure(session.error())) {
        fail("token refused: " + session.error().message + " (pass the daemon's token with --token)");
        return;
      }
      status.state = SourceStatus::State::Waiting;
      status.message = session.error().message;
      publish_status(status);
      if (!sleep_for(stop, kRetryDelay)) return;
      continue;
    }
    std::tie(status.backend, status.board) = backend_and_board(session->device_json);
    status.mirror = mirror_enabled(session->device_json);
    status.frames_note = frames_note(session->device_json);
    status.accuracy = device_accuracy(session->device_json);
    status.device = session->device_kind == protocol::DeviceKind::Spigpu
                        ? std::string()
                        : std::string(protocol::device_kind_info(session->device_kind).label);
    const auto max_fps = static_cast<std::uint16_t>(std::min(config_.max_fps, 65535u));
    const auto subscribe = [&](protocol::FrameSource p) {
      // The board in the original 3-byte form, which daemons without mirror mode understand too.
      std::optional<protocol::FrameSource> source;
      if (p != protocol::FrameSource::Board) source = p;
      return c.subscribe(protocol::Subscribe{protocol::FrameFormat::Native, max_fps, source}, kHandshakeTimeout);
    };
    if (auto sub = subscribe(picture); !sub) {
      if (client::is_protocol_error(sub.error(), protocol::ErrorCode::Unavailable)) {
        // Asked for on the command line (--source): retrying cannot help.
        fail("cannot show the " + picture_name(picture) + ": " + sub.error().message);
        c.close();
        return;
      }
      status.state = SourceStatus::State::Waiting;
      status.message = "subscribe failed: " + sub.error().message;
      publish_status(status);
      if (!sleep_for(stop, kRetryDelay)) return;
      continue;
    }
    ever_connected = true;
    status.state = SourceStatus::State::Streaming;
    status.message.clear();
    publish_status(status);
    log->info("subscribed to {} ({}, max {} fps)", display_address_, picture_name(picture), max_fps);

    auto next_mirror_poll = std::chrono::steady_clock::now();
    while (!stop.stop_requested()) {
      if (auto want = take_picture_request(); want && *want != picture) {
        if (auto sub = subscribe(*want); sub) {
          picture = *want;
          status.picture = picture;
          status.picture_problem.clear();
          log->info("now showing the {}", picture_name(picture));
        } else {
          // Refused (no mirror mode) or the connection broke (next_frame below notices).
          status.picture_problem = "cannot show the " + picture_name(*want) + ": " + sub.error().message;
        }
        publish_status(status);
      }
      if (status.mirror && std::chrono::steady_clock::now() >= next_mirror_poll) {
        next_mirror_poll = std::chrono::steady_clock::now() + kMirrorStatusInterval;
        if (auto reply = c.status(kHandshakeTimeout); reply) {
          if (auto counts = mirror_counts(*reply);
              counts && (status.compared != counts->first || status.mismatches != counts->second)) {
            status.compared = counts->first;
            status.mismatches = counts->second;
            publish_status(status);
          }
        }
      }
      auto frame = c.next_frame(kPollInterval);
      if (frame) {
        publish_frame(to_viewer_frame(std::move(*frame)));
        continue;
      }
      if (frame.error().code == client::kTimeoutError) continue;
      log->info("connection to {} lost: {}", display_address_, frame.error().message);
      status.state = SourceStatus::State::Waiting;
      status.message = frame.error().message;
      publish_status(status);
      break;
    }
    if (stop.stop_requested()) {
      c.close();
      return;
    }
    if (!sleep_for(stop, kRetryDelay)) return;
  }
}

}  // namespace gpubridge::viewer
