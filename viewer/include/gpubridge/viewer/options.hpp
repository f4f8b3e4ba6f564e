#pragma once
// gpubridge-view's command line.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/messages.hpp"
#include "gpubridge/viewer/layout.hpp"

namespace gpubridge::viewer {

struct Options {
  std::string connect;                  // daemon address; empty = the default socket
  std::string token;                    // sent in HELLO
  std::optional<std::uint32_t> frames;  // exit after the N-th received frame (1-based)
  std::string screenshot;               // with frames: save that frame's pixels here
  std::string grab_window;              // with frames: save the window's back buffer here
  bool offscreen = false;               // hidden window, or no window at all without a display
  bool json = false;                    // machine-readable summary on stdout
  bool wait = false;                    // wait for the daemon at startup instead of failing
  double timeout_s = 30;                // headless: give up when frame N has not arrived by then
  std::optional<unsigned> max_fps;      // subscription rate; default: the display's refresh rate
  protocol::FrameSource source = protocol::FrameSource::Board;  // mirror mode: board | sim | diff
  ScaleMode scale = ScaleMode::Fit;
  bool flip = false;
  bool overlay = true;
  std::optional<std::pair<int, int>> window_size;
  std::string screenshot_dir = ".";     // where the S key saves
  std::string test_source;              // hidden: generate frames instead of connecting
  std::string press;                    // hidden: keys typed once the first frame arrived (tests)
  std::string log_level = "warn";
};

// What main() should do after parsing.
struct ParsedCommandLine {
  enum class Action { Run, Exit } action = Action::Run;
  int exit_code = 0;   // for Exit: 0 after --help/--version
  std::string output;  // for Exit: text to print on stdout
  Options options;
};

// Parses argv; usage errors come back as Error (message says which option and what is allowed).
Result<ParsedCommandLine> parse_command_line(int argc, const char* const* argv);

}  // namespace gpubridge::viewer
