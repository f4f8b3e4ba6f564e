#include "window_app.hpp"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <iostream>

#include <fmt/format.h>

#include "capture.hpp"
#include "exit_codes.hpp"
#include "gl_renderer.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/viewer/clock.hpp"
#include "gpubridge/viewer/overlay.hpp"
#include "gpubridge/viewer/rate_meter.hpp"
#include "gpubridge/viewer/text_panel.hpp"
#include "headless.hpp"

namespace gpubridge::viewer {
namespace {

std::string& glfw_error_text() {
  static std::string text;  // GLFW's error callback has no user pointer; executable-only state
  return text;
}

void on_glfw_error(int code, const char* description) {
  glfw_error_text() = fmt::format("GLFW error {:#x}: {}", code, description ? description : "?");
}

constexpr auto kOverlayRefreshNs = 250'000'000ull;  // fps figures change; redraw the text 4x/s

// State of one window session; GLFW callbacks reach it through the window's user pointer.
class WindowApp {
 public:
  WindowApp(const Options& options, FrameSource& source) : options_(options), source_(source) {
    view_.scale = options.scale;
    view_.flipped = options.flip;
    overlay_on_ = options.overlay;
  }

  int run();

 private:
  static WindowApp& of(GLFWwindow* w) { return *static_cast<WindowApp*>(glfwGetWindowUserPointer(w)); }
  void on_char(unsigned codepoint);
  void toggle_zoom(ScaleMode mode) { view_.scale = view_.scale == mode ? ScaleMode::Fit : mode; }
  void save_screenshot();
  void request_picture(protocol::FrameSource picture);
  bool take_frame();  // true when a new frame was uploaded
  void refresh_overlay();
  void fit_window_to_frame();
  int finish_headless(const Image& grab);

  const Options& options_;
  FrameSource& source_;
  GLFWwindow* window_ = nullptr;
  std::optional<GlRenderer> renderer_;
  ViewState view_;
  bool overlay_on_ = true, help_on_ = false, dirty_ = true, sized_to_frame_ = false;
  std::optional<Frame> current_;  // the frame on screen (device bytes, for S and --screenshot)
  Image current_rgba_;
  std::uint32_t taken_ = 0;
  std::uint64_t drawn_ = 0, pending_swap_ns_ = 0, last_overlay_ns_ = 0;
  std::uint64_t first_draw_ns_ = 0, frames_drawn_ = 0;  // frames (not redraws) shown, for the summary
  double latency_sum_ms_ = 0, latency_max_ms_ = 0;
  std::uint64_t latency_count_ = 0;
  RateMeter received_rate_, drawn_rate_;
  std::string title_;
  std::vector<std::string> overlay_text_;
};

void WindowApp::on_char(unsigned codepoint) {
  switch (codepoint) {
    case 's': case 'S': save_screenshot(); break;
    case 'f': case 'F': view_.flipped = !view_.flipped; break;
    case 'i': case 'I': toggle_zoom(ScaleMode::Integer); break;
    case '1': toggle_zoom(ScaleMode::Zoom1); break;
    case '2': toggle_zoom(ScaleMode::Zoom2); break;
    case '3': toggle_zoom(ScaleMode::Zoom3); break;
    case 'p': case 'P': view_.paused = !view_.paused; break;
    case 'o': case 'O': overlay_on_ = !overlay_on_; break;
    case 'b': case 'B': request_picture(protocol::FrameSource::Board); break;
    case 'm': case 'M': request_picture(protocol::FrameSource::Sim); break;
    case 'd': case 'D': request_picture(protocol::FrameSource::Diff); break;
    case '?': help_on_ = !help_on_; break;
    case 'q': case 'Q': glfwSetWindowShouldClose(window_, GLFW_TRUE); break;
    default: return;
  }
  last_overlay_ns_ = 0;  // show the change now
  dirty_ = true;
}

void WindowApp::request_picture(protocol::FrameSource picture) {
  const auto status = source_.status();
  if (!status.mirror && picture != protocol::FrameSource::Board) {
    view_.notice = "no " + picture_name(picture) + ": gpubridged is not in mirror mode (start it with --mirror)";
    return;
  }
  source_.request_picture(picture);
  view_.notice = "showing the " + picture_name(picture);
}

void WindowApp::save_screenshot() {
  if (!current_) {
    view_.notice = "no frame to save yet";
    return;
  }
  const auto path = screenshot_path(options_.screenshot_dir, current_->number);
  if (auto saved = save_png(path, current_rgba_); !saved) {
    view_.notice = "screenshot failed: " + saved.error().message;
    logger("viewer")->error("{}", view_.notice);
  } else {
    view_.notice = "saved " + path;
    logger("viewer")->info("saved frame {} to {}", current_->number, path);
  }
}

bool WindowApp::take_frame() {
  if (view_.paused) return false;  // the mailbox keeps only the newest: resuming shows it
  auto frame = source_.take_newest();
  if (!frame) return false;
  auto rgba = frame_to_image(*frame);
  if (!rgba) return false;  // take_newest only returns frames that passed frame_problem
  ++taken_;
  renderer_->upload_frame(*rgba);
  current_rgba_ = std::move(*rgba);
  view_.frame = ShownFrame{frame->number, frame->width, frame->height, frame->format, crc_matches(*frame), frame->source};
  pending_swap_ns_ = frame->swap_ns;
  current_ = std::move(frame);
  return true;
}

void WindowApp::refresh_overlay() {
  const auto counters = source_.counters();
  const std::uint64_t now = monotonic_ns();
  received_rate_.sample(now, counters.received);
  view_.status = source_.status();
  view_.fps_received = received_rate_.rate();
  view_.fps_drawn = drawn_rate_.rate();
  view_.dropped = counters.dropped;
  view_.rejected = counters.rejected;
  view_.last_rejection = counters.last_rejection;

  const std::string title = window_title(view_);
  if (title != title_) {
    title_ = title;
    glfwSetWindowTitle(window_, title_.c_str());
  }
  std::vector<std::string> text;
  if (help_on_) {
    text = help_lines();
  } else if (overlay_on_) {
    text = overlay_lines(view_);
  } else if (auto line = status_line(view_.status); !line.empty()) {
    text = {line};  // waiting/failed is always shown, overlay or not
  }
  if (text != overlay_text_) {
    overlay_text_ = std::move(text);
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    renderer_->upload_overlay(render_text_panel(overlay_text_, fb_w >= 1600 ? 2 : 1));
    dirty_ = true;
  }
  last_overlay_ns_ = now;
}

void WindowApp::fit_window_to_frame() {
  // First frame: make the window show it at a whole-number scale, unless the size was given.
  if (sized_to_frame_ || options_.window_size || !current_) return;
  sized_to_frame_ = true;
  int max_w = 1280, max_h = 960;
  if (GLFWmonitor* monitor = glfwGetPrimaryMonitor()) {
    int x = 0, y = 0, w = 0, h = 0;
    glfwGetMonitorWorkarea(monitor, &x, &y, &w, &h);
    if (w > 0 && h > 0) {
      max_w = w * 9 / 10;
      max_h = h * 9 / 10;
    }
  }
  const Size s = initial_window_size(current_->width, current_->height, max_w, max_h);
  glfwSetWindowSize(window_, s.width, s.height);
}

int WindowApp::finish_headless(const Image& grab) {
  CaptureResult result;
  result.frames_taken = taken_;
  result.dropped = source_.counters().dropped;
  const std::uint64_t elapsed_ns = monotonic_ns() - first_draw_ns_;
  if (frames_drawn_ > 1 && elapsed_ns > 0)
    result.fps_drawn = static_cast<double>(frames_drawn_ - 1) * 1e9 / static_cast<double>(elapsed_ns);
  if (latency_count_) {
    result.latency_ms_mean = latency_sum_ms_ / static_cast<double>(latency_count_);
    result.latency_ms_max = latency_max_ms_;
  }
  if (!options_.grab_window.empty()) {
    if (auto saved = save_png(options_.grab_window, grab); !saved) {
      std::cerr << "gpubridge-view: " << saved.error().message << "\n";
      return kExitFailure;
    }
    result.window_grab = options_.grab_window;
  }
  if (auto done = finish_capture(options_, *current_, current_rgba_, result); !done) {
    std::cerr << "gpubridge-view: " << done.error().message << "\n";
    return kExitFailure;
  }
  return kExitOk;
}

int WindowApp::run() {
  const auto [init_w, init_h] = options_.window_size.value_or(std::pair{640, 480});
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, options_.offscreen ? GLFW_FALSE : GLFW_TRUE);
  glfwWindowHint(GLFW_RESIZABLE, options_.window_size && options_.frames ? GLFW_FALSE : GLFW_TRUE);
  window_ = glfwCreateWindow(init_w, init_h, "gpubridge-view", nullptr, nullptr);
  if (!window_) {
    std::cerr << "gpubridge-view: cannot open an OpenGL 3.3 window (" << glfw_error_text()
              << "); use --offscreen without --grab-window to save frames without OpenGL\n";
    return kExitFailure;
  }
  glfwSetWindowUserPointer(window_, this);
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(options_.frames ? 0 : 1);  // headless captures need no vsync pacing
  glfwSetCharCallback(window_, [](GLFWwindow* w, unsigned c) { of(w).on_char(c); });
  glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int) {
    if (key == GLFW_KEY_ESCAPE && action == GLFW_PRESS) glfwSetWindowShouldClose(w, GLFW_TRUE);
  });
  glfwSetFramebufferSizeCallback(window_, [](GLFWwindow* w, int, int) { of(w).dirty_ = true; });
  glfwSetWindowRefreshCallback(window_, [](GLFWwindow* w) { of(w).dirty_ = true; });

  auto renderer = GlRenderer::create();
  if (!renderer) {
    std::cerr << "gpubridge-view: " << renderer.error().message << "\n";
    glfwDestroyWindow(window_);
    return kExitFailure;
  }
  renderer_ = std::move(*renderer);

  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(options_.timeout_s));
  source_.start([] { glfwPostEmptyEvent(); });
  int exit_code = kExitOk;
  while (!glfwWindowShouldClose(window_)) {
    glfwWaitEventsTimeout(0.1);
    const SourceStatus status = source_.status();
    if (status.state == SourceStatus::State::Failed) {
      std::cerr << failure_message(status) << "\n";
      exit_code = kExitUnreachable;
      break;
    }
    if (options_.frames && Clock::now() > deadline) {
      std::cerr << fmt::format("gpubridge-view: frame {} did not arrive within {} s (got {})\n", *options_.frames,
                               options_.timeout_s, taken_);
      exit_code = kExitFailure;
      break;
    }
    const bool new_frame = take_frame();
    if (new_frame) {
      fit_window_to_frame();
      dirty_ = true;
      if (taken_ == 1) {
        for (char key : options_.press) on_char(static_cast<unsigned char>(key));  // scripted keys (tests)
      }
    }
    const std::uint64_t now = monotonic_ns();
    if (new_frame || view_.status.state != status.state || now - last_overlay_ns_ >= kOverlayRefreshNs) {
      refresh_overlay();
    }
    if (!dirty_) continue;
    dirty_ = false;

    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    const Rect r = current_ ? frame_rect(fb_w, fb_h, current_->width, current_->height, view_.scale) : Rect{};
    renderer_->draw(fb_w, fb_h, r, view_.flipped, !overlay_text_.empty());
    const bool capture_now = options_.frames && new_frame && taken_ == *options_.frames;
    Image grab;
    if (capture_now && !options_.grab_window.empty()) grab = renderer_->read_back_buffer(fb_w, fb_h);
    glfwSwapBuffers(window_);
    ++drawn_;
    drawn_rate_.sample(monotonic_ns(), drawn_);
    if (new_frame) {
      if (frames_drawn_++ == 0) first_draw_ns_ = monotonic_ns();
      // swap_ns is the daemon's CLOCK_MONOTONIC: only meaningful on the same machine and never negative.
      const std::uint64_t shown = monotonic_ns();
      if (pending_swap_ns_ && shown >= pending_swap_ns_ && shown - pending_swap_ns_ < 60'000'000'000ull) {
        view_.latency_ms = static_cast<double>(shown - pending_swap_ns_) / 1e6;
        latency_sum_ms_ += *view_.latency_ms;
        latency_max_ms_ = std::max(latency_max_ms_, *view_.latency_ms);
        ++latency_count_;
      } else {
        view_.latency_ms.reset();
      }
    }
    if (capture_now) {
      exit_code = finish_headless(grab);
      break;
    }
  }
  source_.stop();
  renderer_.reset();
  glfwDestroyWindow(window_);
  return exit_code;
}

}  // namespace

bool init_glfw(std::string& why) {
  glfwSetErrorCallback(on_glfw_error);
  if (glfwInit() == GLFW_TRUE) return true;
  why = glfw_error_text().empty() ? "GLFW could not be initialised" : glfw_error_text();
  return false;
}

void terminate_glfw() { glfwTerminate(); }

unsigned display_refresh_rate() {
  GLFWmonitor* monitor = glfwGetPrimaryMonitor();
  const GLFWvidmode* mode = monitor ? glfwGetVideoMode(monitor) : nullptr;
  if (!mode || mode->refreshRate <= 0 || mode->refreshRate > 1000) return 60;
  return static_cast<unsigned>(mode->refreshRate);
}

int run_window(const Options& options, FrameSource& source) {
  WindowApp app(options, source);
  return app.run();
}

}  // namespace gpubridge::viewer
