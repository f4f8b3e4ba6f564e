#pragma once
// Runs the scenes on the simulator through register frames (internal to the bench).
#include <cstdint>

#include "best_frame.hpp"
#include "error_measure.hpp"
#include "gpubridge/sim/options.hpp"

namespace gpubridge::bench {

struct Timing {
  double best_seconds = 0;
  std::uint64_t pixels_covered = 0;  // per frame, from the device's counters
};

// Best time of a frame (clear + the whole scene + drain) by the budget's rule (best_frame.hpp).
Result<Timing> time_sim(const Scene& scene, const sim::AccuracyKnobs& knobs, unsigned threads, const FrameBudget& budget);
// The scene's error subset with depth ALWAYS, no blending, observed pixel by pixel.
Result<RenderedFrame> render_sim_error_pass(const Scene& scene, const sim::AccuracyKnobs& knobs);

}  // namespace gpubridge::bench
