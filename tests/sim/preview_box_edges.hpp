#pragma once
// The plain preview kernel's edge inputs for tests that drive the kernel directly
// (preview_wide16_test.cpp, preview_bands_test.cpp) rather than through a device.
#include <algorithm>
#include <cstdint>
#include <utility>

#include "preview_plain.hpp"

namespace gpubridge::sim::test {

// Biased edge values of the triangle x, y (1/16 pixel, positive winding: D > 0) at the sample
// points of the box whose origin pixel is (bx, by), as setup_coverage makes them.
inline void preview_box_edges(const int* x, const int* y, int bx, int by, PreviewPlain& p) {
  const std::int64_t sx = 16 * bx + 8, sy = 16 * by + 8;
  for (int i = 0; i < 3; ++i) {
    const int a = (i + 1) % 3, b = (i + 2) % 3;
    const std::int64_t dx = x[b] - x[a], dy = y[b] - y[a];
    const bool top_left = (dy == 0 && dx > 0) || dy < 0;
    p.e[i] = dx * (sy - y[a]) - dy * (sx - x[a]) + (top_left ? 0 : -1);
    p.ex[i] = -16 * dy;
    p.ey[i] = 16 * dx;
  }
}

// The pixel box of a triangle: columns [bx0, bx1), rows [by0, by1).
struct PreviewBox {
  int bx0, bx1, by0, by1;
};
// Orders the triangle x, y (1/16 pixel) to positive winding, then puts its edge values at its box's
// origin into p (preview_box_edges) and returns the box.
inline PreviewBox preview_box(int* x, int* y, PreviewPlain& p) {
  if ((x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]) < 0) {
    std::swap(x[1], x[2]);
    std::swap(y[1], y[2]);
  }
  const PreviewBox b{std::min({x[0], x[1], x[2]}) / 16, std::max({x[0], x[1], x[2]}) / 16 + 1,
                     std::min({y[0], y[1], y[2]}) / 16, std::max({y[0], y[1], y[2]}) / 16 + 1};
  preview_box_edges(x, y, b.bx0, b.by0, p);
  return b;
}

}  // namespace gpubridge::sim::test
