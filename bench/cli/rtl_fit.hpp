#pragma once
// The calibration behind the timing presets "up5k" and "ecp5" (`gpubridge bench rtl --fit`):
// non-negative least squares of the gateware-shaped terms of docs/protocol.md section 19 on the
// RTL's cycles per frame, in three stages that follow the gateware's own counters: triangle setup
// (its clocks in setup), the rasteriser walk with the pixel pipeline behind it (its clocks
// walking, memory stalls included) and the rest of the work (command decode, clears, MEM_DATA).
// Each stage fits only the terms that can cost in it; a term's parameter is the sum over stages.
#include <string>
#include <utility>
#include <vector>

#include "gpubridge/rtl/rtl_device.hpp"
#include "gpubridge/sim/timing.hpp"

namespace gpubridge::cli {

struct FitSample {
  sim::DeviceStats work;  // the simulator's counters of the frame
  rtl::RtlCounters rtl;   // the gateware's (differences over the same frame)
  unsigned bpp = 4;       // bytes per pixel of the frame's colour buffer
};

struct TimingFit {
  sim::BoardTiming timing;                                // `base` with the fitted terms
  std::vector<std::pair<std::string, double>> parameters; // apply_timing_setting keys and values (non-zero)
};

// `base` keeps its clocks and link; its cycle terms are replaced by the fit.
TimingFit fit_timing(const std::vector<FitSample>& samples, const sim::BoardTiming& base);

// Non-negative least squares: min Σ_r w_r² (Σ_j p_j x_rj − y_r)² over p ≥ 0 (coordinate descent
// on the normal equations, columns scaled to unit norm; the problems here are small).
std::vector<double> nnls(const std::vector<std::vector<double>>& x, const std::vector<double>& y,
                         const std::vector<double>& weight);

}  // namespace gpubridge::cli
