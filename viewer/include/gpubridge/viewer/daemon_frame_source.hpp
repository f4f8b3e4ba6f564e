#pragma once
// Frames from gpubridged: a Client on the source's own thread connects, says HELLO, subscribes
// (native pixel format, at most max_fps) and hands every frame to the newest-only mailbox. When
// the connection drops it reports Waiting and reconnects until stopped.
#include <string>

#include "gpubridge/viewer/frame_source.hpp"

namespace gpubridge::viewer {

struct DaemonSourceConfig {
  std::string address;  // "unix:PATH" | "tcp:HOST:PORT" | "" (default socket)
  std::string token;
  unsigned max_fps = 60;      // 0 = every frame
  bool wait_at_start = false; // keep trying when the very first connection fails
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

}  // namespace gpubridge::viewer
