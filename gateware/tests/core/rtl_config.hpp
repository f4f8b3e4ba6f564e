#pragma once
// CAPS.FEATURES of the Verilated core under test (its FEATURES parameter), so the simulator is
// configured with the same capabilities.
#include <cstdint>

namespace gpubridge::rtl {
#ifndef GPUBRIDGE_RTL_FEATURES
#define GPUBRIDGE_RTL_FEATURES 0x3F
#endif
inline constexpr std::uint8_t kCoreFeatures = GPUBRIDGE_RTL_FEATURES;
}  // namespace gpubridge::rtl
