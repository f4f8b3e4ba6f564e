#pragma once
// The plain preview kernel's inputs for tests that drive the kernel directly
// (preview_wide16_test.cpp, preview_bands_test.cpp, preview_texels_test.cpp) rather than through a
// device: edge values, random planes, and the buffers' origin.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "preview_plain.hpp"
#include "setup.hpp"

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

// Puts the triangle x, y (1/16 pixel) into p as a box of a buffer w pixels wide: its edge values
// (preview_box), planes, width clipped to the buffer, first row, pitch and room to the buffer's
// right edge. The rows it draws (ky0, rows) are the caller's choice; returns the box.
inline PreviewBox place_triangle(int* x, int* y, PreviewPlain& p, const FixedPlanes& planes, unsigned w) {
  const PreviewBox b = preview_box(x, y, p);
  p.planes = &planes;
  p.width = std::min(b.bx1, static_cast<int>(w)) - b.bx0;
  p.pitch = std::size_t{w} * 4;
  p.room = w - static_cast<unsigned>(b.bx0);
  return b;
}

// Random colour and Z planes: any integers (the lanes are modular sums); Z steps small enough that
// a row's depths cross the stored ones, sometimes negative. small_cdy also shifts the colour's y
// steps down by a random amount (tall boxes, where full-size steps would only wrap).
template <class Rng>
void random_planes(Rng& rng, FixedPlanes& planes, bool small_cdy = false) {
  for (unsigned ch = 0; ch < 4; ++ch) {
    planes.c[ch] = static_cast<std::uint32_t>(rng());
    planes.cdx[ch] = static_cast<std::uint32_t>(rng()) >> (rng() % 32);
    planes.cdy[ch] = static_cast<std::uint32_t>(rng());
    if (small_cdy) planes.cdy[ch] >>= rng() % 32;
  }
  planes.z = (std::uint64_t{rng()} << 32 | rng()) >> 8;
  planes.zdx = static_cast<std::uint64_t>(static_cast<std::int64_t>(static_cast<std::int32_t>(rng())) << (rng() % 24));
  planes.zdy = static_cast<std::uint64_t>(static_cast<std::int64_t>(static_cast<std::int32_t>(rng())) << (rng() % 24));
}

// Points p's colour and depth (depth only when on) at the box's first column in row y0 + ky0 of
// buffers buffer_w pixels wide (y0: the box origin's row, place_triangle's by0).
inline void aim_at_rows(PreviewPlain& p, int y0, int ky0, std::uint8_t* color, std::uint8_t* depth,
                        unsigned buffer_w) {
  const std::size_t pitch = std::size_t{buffer_w} * 4;
  const std::size_t origin = static_cast<std::size_t>(y0 + ky0) * pitch + (buffer_w - p.room) * 4;
  p.color = color + origin;
  p.depth = p.depth_on ? depth + origin : nullptr;
}

// Draws case c (a PreviewPlain p, its box origin's row y0 and its starting colour and depth
// buffers) with one instance into copies of its buffers, and returns the counts.
template <class Case>
PreviewCounts draw_case(ShadeRoutine shade, const Case& c, unsigned buffer_w, std::vector<std::uint8_t>& color,
                        std::vector<std::uint8_t>& depth) {
  color = c.color;
  depth = c.depth;
  PreviewPlain p = c.p;
  aim_at_rows(p, c.y0, p.ky0, color.data(), depth.data(), buffer_w);
  return shade(p);
}

// Buffers of w x h pixels (4 bytes each) filled with random bytes.
template <class Rng>
void random_buffer(Rng& rng, std::vector<std::uint8_t>& buffer, unsigned w, unsigned h) {
  buffer.resize(std::size_t{w} * h * 4);
  for (auto& b : buffer) b = static_cast<std::uint8_t>(rng());
}

// A triangle's three vertices anywhere in a w x h pixel buffer (1/16 pixel).
template <class Rng>
void random_points(Rng& rng, int* x, int* y, unsigned w, unsigned h) {
  for (int i = 0; i < 3; ++i) {
    x[i] = static_cast<int>(rng() % (16 * w));
    y[i] = static_cast<int>(rng() % (16 * h));
  }
}

// A random depth test: on unless rng() % off_one_in is 0, any function, writing in two of three.
template <class Rng>
void random_depth_test(Rng& rng, PreviewPlain& p, unsigned off_one_in) {
  constexpr protocol::DepthFunc kFuncs[] = {protocol::DepthFunc::Less, protocol::DepthFunc::LessEqual,
                                            protocol::DepthFunc::Greater, protocol::DepthFunc::GreaterEqual,
                                            protocol::DepthFunc::Always};
  p.depth_on = rng() % off_one_in != 0;
  p.z_func = kFuncs[rng() % 5];
  p.z_write = p.depth_on && rng() % 3 != 0;
}

// Two draws of one case agree: the same counts and the same colour and depth bytes.
inline ::testing::AssertionResult same_draw(const PreviewCounts& got, const PreviewCounts& want,
                                            const std::vector<std::uint8_t>& got_color,
                                            const std::vector<std::uint8_t>& want_color,
                                            const std::vector<std::uint8_t>& got_depth,
                                            const std::vector<std::uint8_t>& want_depth) {
  if (got.scanned != want.scanned || got.covered != want.covered || got.passed != want.passed)
    return ::testing::AssertionFailure() << "counts differ: scanned " << got.scanned << " / " << want.scanned << ", covered "
                                         << got.covered << " / " << want.covered << ", passed " << got.passed << " / "
                                         << want.passed;
  if (got_color != want_color) return ::testing::AssertionFailure() << "colour bytes differ";
  if (got_depth != want_depth) return ::testing::AssertionFailure() << "depth bytes differ";
  return ::testing::AssertionSuccess();
}

}  // namespace gpubridge::sim::test
