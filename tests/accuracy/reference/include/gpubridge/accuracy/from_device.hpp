#pragma once
// Converts the host library's device triangle (register values) into the reference rasteriser's own
// triangle type. Header-only so the reference library itself stays independent of the host code;
// the suite and the benchmark, which both use the host library, share this one conversion.
#include <cstdint>

#include "gpubridge/accuracy/reference.hpp"
#include "gpubridge/geometry/convert.hpp"

namespace gpubridge::accuracy {

inline FixedTriangle to_fixed(const geometry::DeviceTriangle& t) {
  FixedTriangle f;
  for (int i = 0; i < 3; ++i) {
    f[i].x = t[i].x;
    f[i].y = t[i].y;
    f[i].z = t[i].z & 0xFFFFFFu;
    f[i].rgba = {std::uint8_t(t[i].rgba >> 24), std::uint8_t(t[i].rgba >> 16), std::uint8_t(t[i].rgba >> 8),
                 std::uint8_t(t[i].rgba)};
    f[i].q = t[i].q;
    f[i].s = t[i].s;
    f[i].t = t[i].t;
  }
  return f;
}

}  // namespace gpubridge::accuracy
