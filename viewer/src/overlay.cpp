#include "gpubridge/viewer/overlay.hpp"

#include <fmt/format.h>

namespace gpubridge::viewer {
namespace {

// "sim", "usb/ulx3s"; a device other than spigpu says its kind first: "DMC-1 sim".
std::string device_name(const SourceStatus& s) {
  if (s.backend.empty()) return "?";
  const std::string kind = s.device.empty() ? "" : s.device + " ";
  return kind + (s.board.empty() ? s.backend : s.backend + "/" + s.board);
}

// The picture on screen: the shown frame's own source once one arrived, else the one asked for.
protocol::FrameSource shown_picture(const ViewState& v) { return v.frame ? v.frame->source : v.status.picture; }

}  // namespace

std::string accuracy_text(const ViewState& v) {
  // Mirror mode: the simulator picture is the exact model's, whatever the daemon's --accuracy; the
  // diff compares the board with it.
  if (v.status.mirror && shown_picture(v) != protocol::FrameSource::Board) return "accuracy exact";
  return v.status.accuracy.empty() ? std::string() : "accuracy " + v.status.accuracy;
}

std::string picture_line(const ViewState& v) {
  if (!v.status.mirror) return {};
  std::string line = "showing " + picture_name(shown_picture(v));
  if (v.frame && v.frame->source != v.status.picture) line += " (switching to " + picture_name(v.status.picture) + ")";
  if (v.status.mismatches && v.status.compared)
    line += fmt::format("  mismatches {} of {} frames", *v.status.mismatches, *v.status.compared);
  return line;
}

std::string status_line(const SourceStatus& s) {
  using State = SourceStatus::State;
  const std::string why = s.message.empty() ? "" : " (" + s.message + ")";
  switch (s.state) {
    case State::Connecting: return "connecting to gpubridged at " + s.address + "...";
    case State::Streaming: return {};
    case State::Waiting: return "waiting for gpubridged at " + s.address + why;
    case State::Failed: return "cannot show frames from " + s.address + why;
    case State::Finished: return "frame source at " + s.address + " finished";
  }
  return {};
}

std::vector<std::string> overlay_lines(const ViewState& v) {
  std::vector<std::string> lines;
  lines.push_back(fmt::format("{}  {}", v.status.address, device_name(v.status)));
  if (!v.status.frames_note.empty()) lines.push_back("frames: " + v.status.frames_note);
  if (auto s = status_line(v.status); !s.empty()) lines.push_back(std::move(s));
  if (auto p = picture_line(v); !p.empty()) lines.push_back(std::move(p));
  if (!v.status.picture_problem.empty()) lines.push_back(v.status.picture_problem);
  if (v.frame) {
    const std::string accuracy = accuracy_text(v);
    lines.push_back(fmt::format("frame {}  {}x{} {}{}{}", v.frame->number, v.frame->width, v.frame->height,
                                protocol::to_string(v.frame->format), accuracy.empty() ? "" : "  " + accuracy,
                                v.frame->crc_ok ? "" : "  CRC MISMATCH"));
  } else {
    lines.push_back("no frame yet");
  }
  lines.push_back(fmt::format("fps received {:.1f}  drawn {:.1f}  dropped {}", v.fps_received, v.fps_drawn,
                              v.dropped));
  lines.push_back(v.latency_ms ? fmt::format("latency swap->display {:.1f} ms", *v.latency_ms)
                               : std::string("latency swap->display n/a"));
  std::string mode = "scale " + to_string(v.scale);
  if (v.flipped) mode += "  flipped";
  if (v.paused) mode += "  PAUSED";
  lines.push_back(std::move(mode));
  if (v.rejected) lines.push_back(fmt::format("{} frames refused: {}", v.rejected, v.last_rejection));
  if (!v.notice.empty()) lines.push_back(v.notice);
  lines.push_back("? help");
  return lines;
}

std::vector<std::string> help_lines() {
  return {
      "gpubridge-view keys",
      "  S      save the frame's pixels as PNG",
      "  F      flip vertically",
      "  I      integer scaling on/off",
      "  1 2 3  zoom 1:1 2:1 3:1 (again: fit)",
      "  P      pause / resume",
      "  O      overlay on/off",
      "  B      board picture (gpubridged --mirror)",
      "  M      simulator (model) picture",
      "  D      diff: equal pixels grey, differing magenta",
      "  ?      this help",
      "  Q Esc  quit",
  };
}

std::string window_title(const ViewState& v) {
  std::string title = "gpubridge-view - " + v.status.address + " - " + device_name(v.status);
  if (v.status.mirror) title += " - " + picture_name(shown_picture(v));
  if (v.frame) {
    title += fmt::format(" - {}x{} {}", v.frame->width, v.frame->height, protocol::to_string(v.frame->format));
  }
  if (v.status.state == SourceStatus::State::Waiting) title += " [waiting]";
  if (v.status.state == SourceStatus::State::Failed) title += " [failed]";
  if (v.paused) title += " [paused]";
  return title;
}

}  // namespace gpubridge::viewer
