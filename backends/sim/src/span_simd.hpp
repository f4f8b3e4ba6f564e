#pragma once
// The vectorised span routine for draws into an RGBA8888, RGB565 or RGBA2222 buffer (packed formats
// quantised with the optional ordered or temporal dither, section 11): optional depth test/write,
// optional texture (any format inside VRAM, nearest or bilinear, modulate or decal; the texture
// disjoint from both buffers), optional blend (ALPHA, ADD, MULTIPLY) and write mask, both buffers
// inside VRAM and disjoint. Eight pixels per step: lanes k = 0..7
// hold (q, r) of each attribute plane for x + k and advance by (Q8, R8) = divmod(8·step) with
// add, add, compare, and, subtract, subtract — no division per pixel, and integer-exact, so the
// output equals the scalar routine's byte for byte (tests compare them).
#include <cstdint>

#include "texture_lanes.hpp"

namespace gpubridge::sim {

struct SimdSpan {
  static constexpr unsigned kPlanes = 8;  // R, G, B, A, Z, S, T, Q (setup.hpp's attribute order)
  std::uint32_t q0[kPlanes], r0[kPlanes];      // (q, r) at the span's first pixel
  std::uint32_t qk[kPlanes][8], rk[kPlanes][8];  // offsets of lane k: divmod(k·step), rk < den
  std::uint32_t q8[kPlanes], r8[kPlanes];  // advance per 8 pixels (r8 < den)
  std::uint32_t den = 1;                   // < 2^30, so r + r8 < 2^31
  std::uint32_t flat = 0;                  // colour word (memory order R,G,B,A) when !gouraud
  std::uint32_t zmask = 0xFFFFFF;
  std::uint8_t* color = nullptr;           // first pixel of the span
  std::uint8_t* depth = nullptr;           // first depth word of the span (when z_test or z_write)
  unsigned count = 0;                      // pixels in the span
  unsigned room = 0;                       // pixels from the span's first to the end of its buffer row (>= count)
  unsigned z_func = 0;                     // protocol::DepthFunc
  unsigned blend = 0;                      // protocol::BlendMode (0 = off)
  std::uint32_t keep = 0;                  // bytes of the colour word the write mask keeps
  unsigned format = 0;                     // protocol::PixelFormat of the colour buffer
  std::uint32_t keep_packed = 0;           // packed formats: the stored bits the write mask keeps
  std::uint32_t bayer[8] = {};             // packed formats with dither: threshold index of lane k's pixel
                                           // (the pattern repeats every 4 pixels, so every chunk of 8 shares it)
  bool temporal = false;                   // packed formats: the temporal quantiser (section 11) on `bayer`
  bool gouraud = false, z_test = false, z_write = false;
  // Texture stage (texture.tex == nullptr: untextured). Texels are fetched lane by lane (the
  // texel coordinates need 64-bit products and a table lookup); filter and combine run in lanes.
  TextureLanes texture;
};

// Returns the number of pixels that passed the depth test (all of them without a test).
std::uint64_t shade_span_simd(const SimdSpan& span);

}  // namespace gpubridge::sim
