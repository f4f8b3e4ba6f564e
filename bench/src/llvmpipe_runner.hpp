#pragma once
// Runs the scenes on llvmpipe in a child process per thread count (internal to the bench).
#include <string>
#include <vector>

#include "best_frame.hpp"
#include "error_measure.hpp"

namespace gpubridge::bench {

struct LlvmpipeResult {
  std::string renderer;
  std::vector<double> seconds;                  // best frame time per scene
  std::vector<unsigned long long> pixel_sum;    // sum of the RGBA bytes of the last timed frame
  std::vector<std::optional<ErrorStats>> error; // per scene (only when measured)
};

// The best frame per scene by the budget's rule (best_frame.hpp), as the simulator's.
// lp_threads: LP_NUM_THREADS (0 = rasterise in the calling thread). Errors say why llvmpipe is
// unavailable; the caller then omits the llvmpipe rows.
Result<LlvmpipeResult> run_llvmpipe(const std::vector<Scene>& scenes, const std::vector<ReferenceFrame>& refs,
                                    unsigned lp_threads, const FrameBudget& budget, bool measure_error);

}  // namespace gpubridge::bench
