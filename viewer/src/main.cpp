// gpubridge-view: shows the frames gpubridged scans out (issue 6). See docs/viewer.md.
#include <cstdlib>
#include <iostream>
#include <memory>

#include "exit_codes.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/viewer/daemon_frame_source.hpp"
#include "gpubridge/viewer/options.hpp"
#include "gpubridge/viewer/test_frame_source.hpp"
#include "headless.hpp"
#include "window_app.hpp"

namespace {

using namespace gpubridge::viewer;

// --frames captures want every frame (so "the N-th" is well defined); an interactive window asks
// for no more than the display can show.
unsigned subscription_rate(const Options& o, bool have_display) {
  if (o.max_fps) return *o.max_fps;
  if (o.frames) return 0;
  return have_display ? display_refresh_rate() : 60;
}

gpubridge::Result<std::unique_ptr<FrameSource>> make_source(const Options& o, unsigned max_fps) {
  if (!o.test_source.empty()) {
    auto spec = parse_test_pattern_spec(o.test_source);
    if (!spec) return spec.error();
    return std::unique_ptr<FrameSource>(std::make_unique<TestFrameSource>(*spec));
  }
  DaemonSourceConfig config{o.connect, o.token, max_fps, o.wait, o.source};
  return std::unique_ptr<FrameSource>(std::make_unique<DaemonFrameSource>(std::move(config)));
}

}  // namespace

int main(int argc, char** argv) {
  auto parsed = parse_command_line(argc, argv);
  if (!parsed) {
    std::cerr << "gpubridge-view: " << parsed.error().message << "\n";
    return kExitUsage;
  }
  if (parsed->action == ParsedCommandLine::Action::Exit) {
    std::cout << parsed->output;
    return parsed->exit_code;
  }
  const Options& options = parsed->options;
  gpubridge::init_logging(options.log_level);

  std::string no_display_reason;
  const bool have_display = init_glfw(no_display_reason);
  if (!have_display) {
    if (!options.offscreen || !options.grab_window.empty() || !options.frames) {
      std::cerr << "gpubridge-view: no display (" << no_display_reason << "); set DISPLAY"
                << (options.grab_window.empty() ? ", or use --offscreen --frames N --screenshot PATH" : "")
                << "\n";
      return kExitFailure;
    }
  }
  auto source = make_source(options, subscription_rate(options, have_display));
  if (!source) {
    std::cerr << "gpubridge-view: " << source.error().message << "\n";
    if (have_display) terminate_glfw();
    return kExitUsage;
  }
  int code = kExitOk;
  if (have_display) {
    code = run_window(options, **source);
    (*source)->stop();
    terminate_glfw();
  } else {
    code = run_headless(options, **source);
  }
  return code;
}
