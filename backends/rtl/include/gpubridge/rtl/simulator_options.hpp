#pragma once
// The simulator configured as the same device as a gateware profile (its CAPS and ID.VARIANT), the
// judge of every co-simulation. Header-only: gpubridge_rtl does not link the simulator; whoever
// includes this does.
#include "gpubridge/rtl/gateware_profile.hpp"
#include "gpubridge/sim/options.hpp"

namespace gpubridge::rtl {

inline sim::DeviceOptions simulator_options(const GatewareCaps& c) {
  sim::DeviceOptions o;
  o.vram_bytes = std::uint64_t{c.vram_kib} * 1024;
  o.max_width = c.max_width;
  o.max_height = c.max_height;
  o.fifo_depth = c.fifo_depth;
  o.features = c.features;
  o.features2 = c.features2;
  o.variant = c.variant;
  o.sdram_rows = true;  // its counters feed the timing model checked against the gateware's cycles
  return o;
}

}  // namespace gpubridge::rtl
