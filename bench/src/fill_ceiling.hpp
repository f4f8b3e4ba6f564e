#pragma once
// Measures the FillCeiling of accuracy_bench.hpp (internal to the bench).
#include <vector>

#include "gpubridge/bench/accuracy_bench.hpp"

namespace gpubridge::bench {

// One entry per thread count; quick: smaller buffers and fewer passes (figures not meaningful).
std::vector<FillCeiling> measure_fill_ceiling(const std::vector<unsigned>& threads, unsigned runs, bool quick);

}  // namespace gpubridge::bench
