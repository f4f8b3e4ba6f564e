#pragma once
// Calibration streams of `gpubridge bench rtl --fit`: for every render-state class a gateware
// profile has (DeviceStats::by_mode), one frame per triangle shape (small, tall, wide, fat;
// textured fat ones nearest and bilinear) plus clears of different shapes, so the fit can tell
// per-triangle, per-row, per-column and per-pixel costs apart, which the example scenes (mostly
// one class, similar triangles) confound. Seeded: the same streams every run.
#include <string>
#include <vector>

#include "gpubridge/protocol/command_stream.hpp"

namespace gpubridge::cli {

struct CalibrationStream {
  std::string name;  // "calib/CLASS/SHAPE"
  protocol::CommandStream stream;
};

// 160 × 120 RGB565; with `depth` (CAPS2.FEATURES2 bit 0, the ecp5) a depth buffer, its clears and
// the depth classes; with `texturing` (CAPS.FEATURES bit 7, the ecp5) also the textured classes,
// their 64 × 64 RGBA8888 texture uploaded in the frame, and RGBA8888 colour buffers.
std::vector<CalibrationStream> calibration_streams(bool texturing, bool depth);

}  // namespace gpubridge::cli
