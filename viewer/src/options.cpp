#include "gpubridge/viewer/options.hpp"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "gpubridge/common/log.hpp"
#include "gpubridge/version.hpp"

namespace gpubridge::viewer {
namespace {

Result<ScaleMode> parse_scale(const std::string& s) {
  if (s == "fit") return ScaleMode::Fit;
  if (s == "integer") return ScaleMode::Integer;
  if (s == "1") return ScaleMode::Zoom1;
  if (s == "2") return ScaleMode::Zoom2;
  if (s == "3") return ScaleMode::Zoom3;
  return make_error(fmt::format("--scale {}: expected fit, integer, 1, 2 or 3", s));
}

Result<std::pair<int, int>> parse_size(const std::string& s) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' || w < 16 || h < 16 || w > 8192 ||
      h > 8192) {
    return make_error(fmt::format("--size {}: expected WIDTHxHEIGHT, each 16 .. 8192 (e.g. 640x480)", s));
  }
  return std::pair{w, h};
}

}  // namespace

Result<ParsedCommandLine> parse_command_line(int argc, const char* const* argv) {
  ParsedCommandLine parsed;
  Options& o = parsed.options;
  CLI::App app{
      "gpubridge-view: shows the frames gpubridged scans out, as they arrive.\n"
      "Keys: S screenshot, F flip, I integer scaling, 1/2/3 zoom, P pause, O overlay, ? help, Q/Esc quit;\n"
      "with gpubridged --mirror: B board, M simulator (model), D diff (differing pixels magenta).\n"
      "Headless: --frames N --screenshot out.png [--offscreen] saves the N-th received frame and exits."};
  app.name("gpubridge-view");
  app.set_version_flag("--version", std::string("gpubridge-view ") + kVersion);
  std::string scale = "fit", size, source = "board";
  unsigned max_fps = 0;
  std::uint32_t frames = 0;
  app.add_option("--connect", o.connect, "daemon address: unix:PATH or tcp:HOST:PORT (default: the local socket)");
  app.add_option("--token", o.token, "access token for the daemon (when it requires one)");
  app.add_option("--frames", frames, "exit after the N-th received frame (1 = the first)")
      ->check(CLI::Range(1u, 1'000'000u));
  app.add_option("--screenshot", o.screenshot, "with --frames: save that frame's own pixels as PNG");
  app.add_option("--grab-window", o.grab_window,
                 "with --frames: save the window's back buffer (what is drawn) as PNG after that frame");
  app.add_flag("--offscreen", o.offscreen, "no visible window (hidden GL window; no GL at all without a display)");
  app.add_flag("--json", o.json, "print a JSON summary on stdout (headless use)");
  app.add_flag("--wait", o.wait, "wait for the daemon to appear instead of failing when it is not running");
  app.add_option("--timeout", o.timeout_s, "with --frames: seconds to wait for the N-th frame (default 30)")
      ->check(CLI::Range(0.1, 86400.0));
  app.add_option("--max-fps", max_fps, "frames per second to ask for (default: the display's refresh rate; 0 = all)")
      ->check(CLI::Range(0u, 1000u));
  app.add_option("--scale", scale, "fit | integer | 1 | 2 | 3 (default fit)");
  app.add_option("--source", source,
                 "board | sim | diff: the board's frames, the simulator's, or their difference (sim and diff "
                 "need gpubridged --mirror; default board)");
  app.add_flag("--flip", o.flip, "start flipped vertically (boards whose scanout starts at the bottom)");
  app.add_flag("!--no-overlay", o.overlay, "start with the overlay hidden");
  app.add_option("--size", size, "initial window size WIDTHxHEIGHT (default: the frame at a whole-number scale)");
  app.add_option("--screenshot-dir", o.screenshot_dir, "directory for screenshots taken with the S key");
  app.add_option("--log-level", o.log_level, gpubridge::log_levels_text() + " (default warn)")
      ->check(CLI::IsMember(std::vector<std::string>(gpubridge::kLogLevels.begin(), gpubridge::kLogLevels.end())));
  // Hidden (empty group): a generated test pattern instead of the daemon, for tests of the display.
  app.add_option("--test-source", o.test_source, "WxH[:FORMAT][@FPS]")->group("");
  app.add_option("--press", o.press, "keys typed when the first frame arrives")->group("");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    parsed.action = ParsedCommandLine::Action::Exit;
    parsed.output = app.help();
    return parsed;
  } catch (const CLI::CallForVersion&) {
    parsed.action = ParsedCommandLine::Action::Exit;
    parsed.output = std::string("gpubridge-view ") + kVersion + "\n";
    return parsed;
  } catch (const CLI::ParseError& e) {
    return make_error(std::string(e.what()) + " (see gpubridge-view --help)", 2);
  }

  // Range checks let NaN through (every comparison with NaN is false): check it positively.
  if (!(o.timeout_s >= 0.1 && o.timeout_s <= 86400.0))
    return make_error("--timeout: expected seconds from 0.1 to 86400", 2);
  auto picture = protocol::parse_frame_source(source);
  if (!picture) return make_error(fmt::format("--source {}: expected board, sim or diff", source), 2);
  o.source = *picture;
  auto scale_mode = parse_scale(scale);
  if (!scale_mode) return Error{scale_mode.error().message, 2};
  o.scale = *scale_mode;
  if (!size.empty()) {
    auto s = parse_size(size);
    if (!s) return Error{s.error().message, 2};
    o.window_size = *s;
  }
  if (app.count("--max-fps")) o.max_fps = max_fps;
  if (app.count("--frames")) o.frames = frames;
  if (!o.frames && (!o.screenshot.empty() || !o.grab_window.empty())) o.frames = 1;
  if (o.frames && o.screenshot.empty() && o.grab_window.empty() && !o.json) {
    return make_error("--frames needs --screenshot PATH, --grab-window PATH or --json (what to do with the frame)",
                      2);
  }
  return parsed;
}

}  // namespace gpubridge::viewer
