#pragma once
// Triangle setup (docs/protocol.md sections 8-9): area D, edge functions with top-left biases, the
// clipped bounding box, and each interpolated attribute as an exact plane stepper.
//
// An attribute's value at a pixel is a0 + floor(M / (2D)) with M = 2·(Δ1·b1 + Δ2·b2) + D linear in
// (x, y) (Δi = ai − a0, bi the barycentric edge values). A Plane keeps (q, r) = floor-divmod of M by
// den = 2D and steps it with additions only: q += qx; r += rx; if (r >= den) { r -= den; ++q; }.
// That yields exactly floor((2N + D) / (2D)) of section 9 at every pixel, with no division per
// pixel and no drift.
#include <cmath>
#include <cstdint>

#include "draw_state.hpp"
#include "fixed_point.hpp"

namespace gpubridge::sim {

struct Vertex {
  std::int32_t x = 0, y = 0;  // 1/16 pixel (s12.4 sign-extended)
  std::uint32_t z = 0;        // 24 bits
  std::uint8_t c[4] = {0, 0, 0, 0};  // R, G, B, A
  std::uint32_t q = 0;        // u0.32
  std::int32_t s = 0, t = 0;  // s8.24
};

// Attribute order inside a triangle.
enum Attr : unsigned { kR = 0, kG, kB, kA, kZ, kS, kT, kQ, kAttrCount };

struct Plane {
  std::int64_t q = 0, r = 0;    // value and remainder at the bounding-box origin
  std::int64_t qx = 0, rx = 0;  // step for x + 1 (rx in [0, den))
  std::int64_t qy = 0, ry = 0;  // step for y + 1
  bool constant = true;         // every vertex equal: value is q everywhere, no stepping

  // (q, r) advanced by k steps of (qs, rs) (k >= 0), exact.
  static void advance(std::int64_t& q, std::int64_t& r, std::int64_t qs, std::int64_t rs, std::int64_t k,
                      std::int64_t den) {
    const i128 rr = i128{r} + i128{rs} * k;
    const DivMod d = floor_divmod128(rr, den);
    q += qs * k + d.q;
    r = d.r;
  }
};

struct Edge {
  std::int64_t e = 0;   // E + bias at the bounding-box origin's sample point
  std::int64_t ex = 0;  // change per pixel in x (= −16·(Yb − Ya))
  std::int64_t ey = 0;  // change per pixel in y (= 16·(Xb − Xa))
};

// The preview path's planes (`--accuracy preview`): a(kx, ky) = base + kx·dx + ky·dy over the box
// (kx, ky from its origin pixel); colour and Z carry +0.5 so truncation rounds them. Double here:
// the preview routine anchors each row's span in double and steps along it in float lanes.
struct FloatPlanes {
  double base[kAttrCount], dx[kAttrCount], dy[kAttrCount];
};

// The same planes in fixed point for the preview's plain-draw kernel (preview_plain.hpp): colour in
// 8.24 and Z in 32.32, each the double value times 2^24 / 2^32 rounded, modulo 2^32 / 2^64 (a
// covered pixel's value is in range; the steps may wrap, and wrap back, on the way to it).
struct FixedPlanes {
  std::uint32_t c[4], cdx[4], cdy[4];  // R, G, B, A (+0.5: the top byte is the rounded value)
  std::uint64_t z, zdx, zdy;           // Z (+0.5: the high word is the rounded value)
};

// x rounded to an integer (halves up), modulo 2^64. Below 2^62 in magnitude (every value but
// those of extreme slivers' far box corners) one conversion; beyond, x is reduced modulo 2^64
// first (exact in double: a multiple of 2^64 subtracted from a value that is a multiple of its own
// unit), so no conversion ever sees a value out of range (NaN becomes 0). The preview's Z planes
// in 32.32 (setup.cpp and the small-triangle setup of preview_plain_kernel.inc).
inline std::uint64_t round_mod64(double x) {
  if (x > -0x1p62 && x < 0x1p62) {
    const double h = x + 0.5;
    auto i = static_cast<std::int64_t>(h);  // truncation; floor below
    i -= static_cast<double>(i) > h;
    return static_cast<std::uint64_t>(i);
  }
  x -= 0x1p64 * std::floor(x * 0x1p-64);
  x = std::floor(x + 0.5);
  return x >= 0 && x < 0x1p64 ? static_cast<std::uint64_t>(x) : 0u;  // 2^64 is 0 modulo 2^64
}

struct Triangle {
  Vertex v[3];          // after the exchange of section 8.1 (D > 0)
  std::int64_t den = 0; // 2D
  Edge edge[3];         // E12, E20, E01 (so edge[i] is the barycentric weight of vertex i)
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // clipped bounding box, inclusive-exclusive
  Plane plane[kAttrCount];
  std::uint8_t flat[4] = {0, 0, 0, 0};  // flat colour (first vertex as listed)
  std::uint64_t index = 0;              // kicked-triangle number
  bool preview = false;                 // set up by setup_triangle_preview: drawn from fplane
  FloatPlanes fplane;                   // preview only (the planes the state needs)
  FixedPlanes xplane;                   // preview of an untextured state: fplane in fixed point
};

// A small triangle of an untextured plain preview draw as its kernel reads it (preview_plain.hpp
// "Small triangles"): what setup_small writes and the row kernel reads, 128 bytes (two cache
// lines) against a Triangle's 920. The renderer's batches carry these for small triangles, so the
// band workers read what the device thread wrote in two lines per triangle (docs/simulator.md,
// "Ninth round" of the preview). Every edge value at a box pixel of such a triangle fits 32 bits
// (below 2^17), so do its steps (16 times a coordinate difference below 2^8).
struct alignas(64) SmallTriangle {
  FixedPlanes xplane;                   // colour in 8.24, Z in 32.32 (the Triangle's xplane)
  std::int32_t e[3], ex[3], ey[3];      // biased edge values at the box origin, steps (Triangle::edge)
  std::int32_t den = 0;                 // 2D
  std::int16_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // clipped bounding box (a clip rectangle is below 2^11)
  std::uint8_t small = 0;               // preview small-triangle kernel + 1 (DrawState::preview_small)
};
static_assert(sizeof(SmallTriangle) == 128, "two cache lines");

// Returns false when the triangle draws nothing (D = 0 or an empty clipped box). Planes are set up
// only for the attributes the state needs (colour when Gouraud, S/T/Q when textured, Z when the
// depth test or depth write is on). subpixel_bits < 4 truncates vertex coordinates first.
bool setup_triangle(const Vertex& a, const Vertex& b, const Vertex& c, const DrawState& state,
                    unsigned subpixel_bits, bool all_attributes, Triangle& out);

// The preview setup (`--accuracy preview`, preview.hpp): the same coverage (D, box, biased integer
// edge functions) and float planes instead of exact ones, from one float reciprocal of D and no
// exact division. With `observing` the exact planes are set up too (the observer reports them).
// Small triangles of a plain untextured draw have a setup of their own, into a SmallTriangle
// (setup_small_preview: the renderer tries it first).
bool setup_triangle_preview(const Vertex& a, const Vertex& b, const Vertex& c, const DrawState& state,
                            unsigned subpixel_bits, bool observing, Triangle& out);

}  // namespace gpubridge::sim
