#pragma once
// The vector routine for small triangles (boxes at most 8 pixels wide), the commonest draw of a
// dense mesh: a store in any pixel format (the packed ones with dither and the write mask on their
// stored bits) with optional texture (as the span routine: texels fetched lane by lane, filter and
// combine in lanes), blend and write mask, optional depth test/write. One row of the box is one
// 8-lane step: the three edge functions, the coverage mask, every attribute plane and the depth
// compare are lane vectors, the colour and depth rows are read and written whole and merged under
// the mask (pixel8.hpp, the pixel stage it shares with the span routine). There is no branch per pixel or per row (a small
// triangle's rows are too short for per-pixel branches to predict), and the arithmetic is the
// exact (q, r) stepping of the scalar routine with 32-bit lanes, so the output is the same byte
// for byte.
//
// The caller guarantees (draw_narrow in rasterizer.cpp checks it): the 8-pixel window lies inside
// the framebuffer row and both buffers inside VRAM; colour and depth buffers do not overlap;
// 8·den < 2^31; every edge value the walk meets fits 32 bits. Lanes outside the box or the
// triangle are written back unchanged; those pixels are on the same row, so they belong to the
// same band worker.
#include <cstddef>
#include <cstdint>

#include "pixel_lanes.hpp"

namespace gpubridge::sim {

struct NarrowTriangle {
  static constexpr unsigned kPlanes = 8;  // R, G, B, A, Z, S, T, Q
  std::int32_t e[3] = {}, ex[3] = {}, ey[3] = {};  // edge values at the first row's box origin, steps
  // Planes at the first row's box origin (r < den) and their steps (rx, ry < den). Only the
  // planes the routine uses are filled (R..A when gouraud, Z when depth or textured, S, T, Q when
  // textured): no zero fill per triangle.
  std::uint32_t q[kPlanes], r[kPlanes];
  std::uint32_t qx[kPlanes], rx[kPlanes], qy[kPlanes], ry[kPlanes];
  std::uint32_t den = 1;
  unsigned width = 0, rows = 0;    // box width (<= 8) and rows to draw
  std::uint8_t* color = nullptr;   // first pixel of the first row
  std::uint8_t* depth = nullptr;   // its depth word (when z_test or z_write)
  std::size_t pitch = 0;           // bytes per depth row (4 per pixel)
  std::size_t color_pitch = 0;     // bytes per colour row (4, 2 or 1 per pixel)
  std::uint32_t bayer[4][8] = {};  // packed formats with dither: threshold index of row (first + j) % 4, lane k
  PixelLanes pixel;                // the draw's depth, texture and colour stages
};

struct NarrowCounts {
  std::uint64_t covered = 0, passed = 0;
};

NarrowCounts shade_narrow_simd(const NarrowTriangle& t);

}  // namespace gpubridge::sim
