#pragma once
// The preview rasteriser (`--accuracy preview`, docs/simulator.md "Preview"): the llvmpipe kind of
// pipeline. Attributes are plane equations anchored once per row at the span's first pixel (in
// double) and evaluated along it in 8 float lanes (no (q, r) stepping, no
// exact division anywhere; perspective texel coordinates from one float divide per 8 lanes), then
// converted — clamped first, so no float-to-integer conversion ever sees an out-of-range value —
// into the integer lanes of the pixel stage the exact vector routines use (pixel8.hpp: depth, texture
// fetch and filter, blend, dither, write mask, store).
//
// Coverage keeps the exact test, top-left rule included, for every coordinate the protocol allows:
// small boxes (at most 8 pixels wide) evaluate the edge functions in float lanes as
// float(E at the row's first pixel, exact in 64 bits) + k·ex, whose sign is the integer value's
// sign (docs/simulator.md proves it); wider rows find their covered span from a float estimate of
// each edge's crossing, checked and corrected against the integer edge values.
//
// Determinism: a pixel's value depends only on its (x, y) and its row's span, never on the band or
// thread that draws it (rows are evaluated from the box origin, not stepped from the band's first
// row), and the file is compiled with -ffp-contract=off, so the AVX2 and the baseline clone round
// the same operations the same way.
//
// The caller (rasterizer.cpp) guarantees: both buffers inside VRAM and disjoint, a texture inside
// VRAM disjoint from both, the colour stage not fully masked.
#include <cstddef>
#include <cstdint>

#include "pixel_lanes.hpp"

namespace gpubridge::sim {

struct PreviewRows {
  static constexpr unsigned kPlanes = 8;  // R, G, B, A, Z, S, T, Q (setup.hpp's attribute order)
  // No default member initialisers for the arrays: this is built per triangle and band, and
  // zeroing them cost 10-px triangles a tenth of their time. The caller fills what is read.
  std::int64_t e[3], ex[3], ey[3];       // biased edge values at the box origin, steps
  double inv_ex[3];                      // boxes wider than 8: 1 / ex (0 when ex = 0), the span estimate
  const double* base = nullptr;          // FloatPlanes (setup.hpp) of the triangle
  const double* dx = nullptr;
  const double* dy = nullptr;
  float scale_u = 0, scale_v = 0;        // textured: 2^(20 + log2 size), texel units of 1/4096 per S/Q
  int width = 0;                         // box width
  int ky0 = 0, rows = 0;                 // first row to draw (relative to the box origin), rows to draw
  std::uint8_t* color = nullptr;         // box origin column, first row drawn
  std::uint8_t* depth = nullptr;         // its depth word (when z_test or z_write)
  std::size_t pitch = 0, color_pitch = 0;  // bytes per depth / colour row
  unsigned room = 0;                     // pixels from the box origin column to the end of a buffer row
  bool dither = false;                   // packed format with dither: bayer[] holds the thresholds
  std::uint32_t bayer[4][4][8];          // when dither: [row % 4][first column % 4][lane] from the box origin
  PixelLanes pixel;
};

struct PreviewCounts {
  std::uint64_t scanned = 0, covered = 0, passed = 0;
};

PreviewCounts shade_preview_simd(const PreviewRows& t);

}  // namespace gpubridge::sim
