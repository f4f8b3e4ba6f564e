#pragma once
// Frames from gpubridged: a Client on the source's own thread connects, says HELLO, subscribes
// (native pixel format, at most max_fps) and hands every frame to the newest-only mailbox. When
// the connection drops it reports Waiting and reconnects until stopped. Against a mirror-mode
// daemon it subscribes to the chosen picture (board, simulator, diff) and polls the daemon's
// mismatch count twice a second.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "gpubridge/viewer/frame_source.hpp"

namespace gpubridge::viewer {

struct DaemonSourceConfig {
  std::string address;  // "unix:PATH" | "tcp:HOST:PORT" | "" (default socket)
  std::string token;
  unsigned max_fps = 60;      // 0 = every frame
  bool wait_at_start = false; // keep trying when the very first connection fails
  protocol::FrameSource picture = protocol::FrameSource::Board;  // --source; B/M/D switch it later
};

class DaemonFrameSource final : public FrameSource {
 public:
  explicit DaemonFrameSource(DaemonSourceConfig config);
  ~DaemonFrameSource() override { stop(); }

 private:
  void run(std::stop_token stop) override;
  DaemonSourceConfig config_;
  std::string display_address_;
};

// Backend and board named by a WELCOME device description ({"backend": "sim", "board": "..."});
// missing keys give empty strings, malformed JSON gives {"?", ""}.
std::pair<std::string, std::string> backend_and_board(const std::string& device_json);
// WELCOME's "mirror" flag (false when absent or malformed).
bool mirror_enabled(const std::string& device_json);
// WELCOME's "frames_note" (docs/protocol.md 17.7): whose frames these are when not the device's own
// (a DMC-1 board shows its simulator's); empty when absent.
std::string frames_note(const std::string& device_json);
// WELCOME's "accuracy" (docs/protocol.md 17.7): "exact", "preview" or "knobs"; empty when absent.
std::string device_accuracy(const std::string& device_json);
// Frames compared and mismatches from a STATUS_REPLY's "mirror" object; nullopt when absent.
std::optional<std::pair<std::uint64_t, std::uint64_t>> mirror_counts(const std::string& status_json);

}  // namespace gpubridge::viewer
