#pragma once
// The Verilated core under test, as configured by CMake (one test executable per profile):
//   GPUBRIDGE_RTL_MODEL        class of the Verilated model (Vcore_ecp5, Vcore_up5k)
//   GPUBRIDGE_RTL_FEATURES     CAPS.FEATURES the simulator is given (the core's FEATURES)
//   GPUBRIDGE_RTL_VRAM_KIB     the profile's VRAM (the core computes addresses for this size)
//   GPUBRIDGE_RTL_TEXTURE      1 when the core samples textures
#include <cstdint>

#ifndef GPUBRIDGE_RTL_MODEL
#error "GPUBRIDGE_RTL_MODEL must name the Verilated model class"
#endif
#define GPUBRIDGE_RTL_STR2(x) #x
#define GPUBRIDGE_RTL_STR(x) GPUBRIDGE_RTL_STR2(x)
#define GPUBRIDGE_RTL_MODEL_HEADER GPUBRIDGE_RTL_STR(GPUBRIDGE_RTL_MODEL.h)

namespace gpubridge::rtl {
inline constexpr std::uint8_t kCoreFeatures = GPUBRIDGE_RTL_FEATURES;
inline constexpr std::uint64_t kCoreVramBytes = std::uint64_t{GPUBRIDGE_RTL_VRAM_KIB} * 1024;
inline constexpr bool kCoreTexture = GPUBRIDGE_RTL_TEXTURE != 0;
}  // namespace gpubridge::rtl
