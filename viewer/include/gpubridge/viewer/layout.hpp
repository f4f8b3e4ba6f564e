#pragma once
// Where the frame goes in the window: aspect ratio kept, optionally whole-number scale factors
// (sharp pixels), or a fixed zoom (1:1, 2:1, 3:1 frame pixels per window pixel).
#include <string>

namespace gpubridge::viewer {

enum class ScaleMode {
  Fit,      // largest size that fits, any factor, aspect ratio kept
  Integer,  // largest whole-number factor that fits (at least 1: may then be cropped)
  Zoom1,    // fixed factors, centred; larger than the window means cropped
  Zoom2,
  Zoom3,
};
std::string to_string(ScaleMode m);

// A rectangle in window framebuffer pixels, origin top-left. Width/height may exceed the window.
struct Rect {
  int x = 0, y = 0, width = 0, height = 0;
  friend bool operator==(const Rect&, const Rect&) = default;
};

// Rectangle the frame covers in a window of window_w x window_h framebuffer pixels. An empty
// window or frame gives an empty rectangle.
Rect frame_rect(int window_w, int window_h, unsigned frame_w, unsigned frame_h, ScaleMode mode);

// The window size (in pixels) that shows a frame at a whole-number factor and fits within max_w x
// max_h: used for the initial window size.
struct Size { int width = 0, height = 0; };
Size initial_window_size(unsigned frame_w, unsigned frame_h, int max_w, int max_h);

}  // namespace gpubridge::viewer
