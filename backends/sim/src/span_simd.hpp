#pragma once
// The vectorised span routine for draws into an RGBA8888, RGB565 or RGBA2222 buffer (packed formats
// quantised with the optional ordered or temporal dither, section 11): optional depth test/write,
// optional texture (any format inside VRAM, nearest or bilinear, modulate or decal; the texture
// disjoint from both buffers), optional blend (ALPHA, ADD, MULTIPLY) and write mask, both buffers
// inside VRAM and disjoint. Eight pixels per step: lanes k = 0..7
// hold (q, r) of each attribute plane for x + k and advance by (Q8, R8) = divmod(8·step) with
// add, add, compare, and, subtract, subtract — no division per pixel, and integer-exact, so the
// output equals the scalar routine's byte for byte (tests compare them). Each chunk goes through
// pixel8.hpp, the pixel stage it shares with the small-triangle routine.
#include <cstdint>

#include "pixel_lanes.hpp"

namespace gpubridge::sim {

struct SimdSpan {
  static constexpr unsigned kPlanes = 8;  // R, G, B, A, Z, S, T, Q (setup.hpp's attribute order)
  std::uint32_t q0[kPlanes], r0[kPlanes];      // (q, r) at the span's first pixel (r0 < den)
  std::uint32_t qx[kPlanes];                   // per-pixel quotient step of each plane, modulo 2^32
  double inv_den = 1;                          // 1 / den (the rasteriser's depth bound query)
  std::uint32_t qk[kPlanes][8], rk[kPlanes][8];  // offsets of lane k: divmod(k·step), rk < den
  std::uint32_t q8[kPlanes], r8[kPlanes];  // advance per 8 pixels (r8 < den)
  std::uint32_t den = 1;                   // < 2^30, so r + r8 < 2^31
  std::uint8_t* color = nullptr;           // first pixel of the span
  std::uint8_t* depth = nullptr;           // first depth word of the span (when z_test or z_write)
  unsigned count = 0;                      // pixels in the span
  unsigned room = 0;                       // pixels from the span's first to the end of its buffer row (>= count)
  std::uint32_t bayer[8] = {};             // packed formats with dither: threshold index of lane k's pixel
                                           // (the pattern repeats every 4 pixels, so every chunk of 8 shares it)
  PixelLanes pixel;                        // the draw's depth, texture and colour stages
};

// Returns the number of pixels that passed the depth test (all of them without a test). Runs the
// widest instance the CPU has (span_simd_isa()); the environment variable GPUBRIDGE_SIM_SPAN_ISA
// (avx512-256, avx2 or baseline; read once per process) caps it, to time the instances against
// each other in one binary and to test each on a CPU that has a wider one.
std::uint64_t shade_span_simd(const SimdSpan& span);

// What shade_span_simd runs for each span of a draw whose stages are px (px.texture.tex, format,
// gouraud): the instance's routine for them, picked once per triangle so that a span pays neither
// the instance look-up nor the dispatch on its stages. Its spans' `pixel` must have the same
// texture, format and colour source as px.
using SpanRoutine = std::uint64_t (*)(const SimdSpan&);
SpanRoutine span_routine(const PixelLanes& px);

// The instruction sets of the span routine's instances (all give the same bytes).
enum class SpanIsa { Baseline, Avx2, Avx512x256, Avx512 };
// The instance shade_span_simd() runs in this process.
SpanIsa span_simd_isa();

}  // namespace gpubridge::sim
