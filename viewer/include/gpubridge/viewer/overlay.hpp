#pragma once
// What the overlay and the window title say. Pure functions of the viewer's state so that the
// wording is tested without a window.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "gpubridge/viewer/frame_source.hpp"
#include "gpubridge/viewer/layout.hpp"

namespace gpubridge::viewer {

struct ShownFrame {  // the frame on screen (metadata only)
  std::uint32_t number = 0;
  unsigned width = 0, height = 0;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  bool crc_ok = true;
  protocol::FrameSource source = protocol::FrameSource::Board;  // which picture it is (mirror mode)
};

struct ViewState {
  SourceStatus status;
  std::optional<ShownFrame> frame;
  double fps_received = 0, fps_drawn = 0;
  std::optional<double> latency_ms;  // swap -> on screen, when known
  std::uint64_t dropped = 0, rejected = 0;
  std::string last_rejection;
  ScaleMode scale = ScaleMode::Fit;
  bool flipped = false, paused = false;
  std::string notice;  // last user-facing event ("saved gpubridge-000042.png")
};

// "waiting for gpubridged at unix:/run/... (connection refused)" and similar; empty while streaming.
std::string status_line(const SourceStatus& s);
std::vector<std::string> overlay_lines(const ViewState& v);
std::vector<std::string> help_lines();
// "gpubridge-view - unix:/run/x.sock - sim/ulx3s - 640x480 RGBA8888 [paused]"; in mirror mode the
// picture follows the device: "... - board/icebreaker - diff board vs simulator - 64x48 RGBA8888".
std::string window_title(const ViewState& v);
// Mirror mode: "showing diff board vs simulator  mismatches 2 of 40 frames"; empty otherwise.
std::string picture_line(const ViewState& v);
// "accuracy preview": how the shown picture was rendered (the simulator picture of a mirror-mode
// daemon is always the exact model's); empty when the daemon does not say.
std::string accuracy_text(const ViewState& v);

}  // namespace gpubridge::viewer
