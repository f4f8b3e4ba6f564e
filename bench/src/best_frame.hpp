// The best frame of a measurement, as every timed side of `gpubridge bench accuracy` takes it (the
// simulator, the llvmpipe peer; bench/llvmpipe/minimal_gl.c follows the same rule in C).
#pragma once

#include <algorithm>

namespace gpubridge::bench {

// At least `runs` timed frames after one warm-up frame, and more until `min_seconds` of timed frames
// have passed. The machines these reports run on are shared: a second vCPU can be busy for tens of
// milliseconds at a time, so five frames of a 2 ms scene can all land in one busy stretch while the
// same five frames of a 90 ms scene cannot. A window in time instead of a count gives every scene the
// same chance of a quiet frame; both sides of a comparison use the same window.
struct FrameBudget {
  unsigned runs = 5;
  double min_seconds = 0;
};

// Frames beyond `runs` stop here whatever the window says (a 0.1 ms frame in a 1 s window).
inline constexpr unsigned kMaxFramesPerMeasurement = 2000;

// `frame()` draws and times one frame and returns its seconds.
template <class Frame>
double best_frame_seconds(const FrameBudget& budget, Frame&& frame) {
  (void)frame();  // warm-up (JIT, page faults, caches)
  double best = 1e30, spent = 0;
  for (unsigned r = 0; r < kMaxFramesPerMeasurement && (r < budget.runs || spent < budget.min_seconds); ++r) {
    const double sec = frame();
    best = std::min(best, sec);
    spent += sec;
  }
  return best;
}

}  // namespace gpubridge::bench
