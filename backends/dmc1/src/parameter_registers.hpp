#pragma once
// The span drawer's persistent registers: parameters set by tag-11 commands and the state spans
// leave behind. All zero at reset; nothing clears them afterwards (docs/dmc1.md, "Persistent state").
#include <cstdint>

#include "fixed_point.hpp"
#include "gpubridge/dmc1/texture_memory.hpp"

namespace gpubridge::dmc1 {

struct ParameterRegisters {
  // UV_OFFSET
  std::int32_t u_offset = 0, v_offset = 0;  // int24
  bool lightmap = false;
  // PLANE_A gradients (int10) and the running dot products (int24); every span advances the dots
  // by one gradient step per row event, so they drift unless PLANE_A is re-sent.
  std::int32_t ny = 0, uy = 0, vy = 0;
  std::int32_t dot_u = 0, dot_v = 0, dot_ray = 0;
  std::int32_t ded = 0;  // last plane's distance (int16 in an int24 register)
  // Terrain
  std::int32_t view_z = 0;          // int16
  std::int32_t cos = 0, sin = 0;    // int13 (RAY_CS reserves 14 bits; values beyond +-4095 wrap)
  std::uint8_t scrh_diff = 0;       // rows the last projected terrain column spanned
  std::uint8_t picked_height = 0;   // first height sample of a span with the pick bit
  // Texture sampler: the id it holds (0 after a background span, so the next textured span binds).
  unsigned sampler_texture = 0;
  TextureBinding binding;

  void advance_dots(std::uint32_t events) {
    dot_ray = wrap24(dot_ray + static_cast<std::int64_t>(events) * ny);
    dot_u = wrap24(dot_u + static_cast<std::int64_t>(events) * uy);
    dot_v = wrap24(dot_v + static_cast<std::int64_t>(events) * vy);
  }
};

}  // namespace gpubridge::dmc1
