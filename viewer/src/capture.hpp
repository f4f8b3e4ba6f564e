#pragma once
// The headless result: the N-th frame saved as PNG (its own pixels), optionally the window grab,
// and a one-line summary (text or JSON) for scripts.
#include <optional>
#include <string>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/viewer/frame.hpp"
#include "gpubridge/viewer/options.hpp"

namespace gpubridge::viewer {

struct CaptureResult {
  std::uint32_t frames_taken = 0;  // N
  std::uint64_t dropped = 0;
  std::string window_grab;  // path when a grab was saved
  // Window runs only: frames drawn per second over the run, and swap-to-display latency.
  std::optional<double> fps_drawn;
  std::optional<double> latency_ms_mean, latency_ms_max;
};

// Saves the frame's pixels (when options ask for it) and prints the summary on stdout.
Result<void> finish_capture(const Options& options, const Frame& frame, const Image& rgba,
                            const CaptureResult& result);

// File name for the S key: DIR/gpubridge-frame-<number>.png (first free name with -2, -3 ...).
std::string screenshot_path(const std::string& dir, std::uint32_t frame_number);

}  // namespace gpubridge::viewer
