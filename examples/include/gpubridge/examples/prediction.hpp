#pragma once
// What frame rate an example would reach on a board (gpubridge-demo fit --timing): the example,
// fitted to the board's device, renders on the exact simulator with that device's CAPS; the
// timing model (docs/protocol.md section 19) turns the counters of one steady frame into board
// cycles at the board's core clock and SPI time at its link clock.
#include <string>

#include "gpubridge/common/result.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/sim/timing.hpp"

namespace gpubridge::examples {

// The parts of a board profile the prediction needs.
struct BoardLink {
  std::string name;
  double clock_mhz = 50;      // core clock
  double spi_clock_mhz = 30;  // bridge SPI clock
  bool readback = true;       // the daemon reads every frame back for its viewers (scanout "readback")
};

struct FramePrediction {
  Fit fit;
  sim::DeviceStats work;          // counters of the frame
  sim::TimingEstimate estimate;   // board cycles, SPI time of the commands, the frame time
  double readback_ms = 0;         // SPI time of reading the frame back (0 without readback)
  double fps = 0;                 // on the board's own display: max(board, commands' SPI time)
  double fps_with_readback = 0;   // as gpubridge-view sees it through the daemon
};

// Fits `ex` to `device` (with `request`), renders frames 0..kGoldenFrame on a simulator with that
// device's CAPS and predicts the last one (the earlier frames carry the texture uploads of setup).
Result<FramePrediction> predict_frame(Example& ex, const DeviceCaps& device, const BoardLink& board,
                                      const FitRequest& request = {});

}  // namespace gpubridge::examples
