#pragma once
// The GLFW window: shows the newest frame, the overlay and help, handles the keys, and in headless
// mode (--frames) saves the N-th frame and/or grabs the window, then exits.
#include "gpubridge/viewer/frame_source.hpp"
#include "gpubridge/viewer/options.hpp"

struct GLFWwindow;

namespace gpubridge::viewer {

// Initialises GLFW. False when there is no display (the message says why).
bool init_glfw(std::string& why);
void terminate_glfw();
// The primary monitor's refresh rate in Hz (60 when unknown).
unsigned display_refresh_rate();

// Runs until quit (or until the N-th frame with --frames). GLFW must be initialised. Returns the
// process exit code.
int run_window(const Options& options, FrameSource& source);

}  // namespace gpubridge::viewer
