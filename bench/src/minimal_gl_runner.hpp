#pragma once
// The yardstick of the llvmpipe peer (issue 17): bench/llvmpipe/minimal_gl.c, a standalone program
// with the plainest Gouraud GL program, run as a child process on the same vertices, thread count and
// resolution as the peer (internal to the bench).
#include <string>

#include "best_frame.hpp"
#include "gpubridge/bench/scenes.hpp"
#include "gpubridge/common/result.hpp"

namespace gpubridge::bench {

// What the minimal program draws: Gouraud triangles, depth LESS + write, no blending, no texture
// (the tri10/tri1k/tri50k scenes, front and random Z).
bool minimal_gl_draws(const Scene& scene);

// The minimal_gl next to this executable (build tree: bench/llvmpipe/minimal_gl), or why there is none.
Result<std::string> find_minimal_gl();

struct MinimalGlRun {
  double best_seconds = 0;
  unsigned long long pixel_sum = 0;  // sum of the RGBA bytes of its last frame
  unsigned frames = 0;               // timed frames (the warm-up not counted)
};

// Writes the scene's vertices (the same floats and RGBA8 colours the peer draws) to a temporary file
// and runs `exe` on them with LP_NUM_THREADS = lp_threads: the best frame by the budget's rule
// (best_frame.hpp; the program's RUNS and MIN_MS arguments).
Result<MinimalGlRun> run_minimal_gl(const std::string& exe, const Scene& scene, unsigned lp_threads,
                                    const FrameBudget& budget);

}  // namespace gpubridge::bench
