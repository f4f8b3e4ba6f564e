#pragma once
// The four colour planes of the exact rasteriser's wide rows in one 4-lane vector (lane i: plane
// kR + i): the cursor at a span's first pixel, its steps and the pixels of a short span. One step
// of all four planes is add, add, compare, and, subtract, subtract on 128-bit vectors (SSE2, the
// baseline ISA rasterizer.cpp is compiled for) where four scalar planes took twenty instructions:
// the fan's 1-3-pixel spans and its empty rows step every plane for every pixel and row
// (docs/simulator.md, "sim-narrow").
//
// Exact under the span routine's condition den < 2^30: remainders stay in [0, den), so r + rs
// < 2^31 compares as a signed 32-bit lane, and quotients are kept modulo 2^32, of which a colour
// reads its low 8 bits.
#include <bit>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace gpubridge::sim {

typedef std::int32_t i32x4 __attribute__((vector_size(16)));

// A step of the four planes, or their values: quotients modulo 2^32, remainders in [0, den).
struct ColorLanes {
  i32x4 q, r;

  // One step s and one carry (den: the triangle's 2D in every lane).
  [[gnu::always_inline]] void step(const ColorLanes& s, i32x4 den) {
    q += s.q;
    r += s.r;
    const i32x4 carry = r >= den;  // -1 where the remainder reached den
    r -= carry & den;
    q -= carry;
  }

  // The colour as the RGBA8888 word stored at a pixel (R in the lowest byte on a little-endian
  // host): each plane's quotient modulo 256.
  [[gnu::always_inline]] std::uint32_t rgba() const {
#if defined(__SSE2__)
    const __m128i bytes = _mm_and_si128(reinterpret_cast<__m128i>(q), _mm_set1_epi32(0xFF));
    const __m128i words = _mm_packs_epi32(bytes, bytes);  // 0..255: no saturation
    return static_cast<std::uint32_t>(_mm_cvtsi128_si32(_mm_packus_epi16(words, words)));
#else
    return (static_cast<std::uint32_t>(q[0]) & 0xFF) | ((static_cast<std::uint32_t>(q[1]) & 0xFF) << 8) |
           ((static_cast<std::uint32_t>(q[2]) & 0xFF) << 16) | (static_cast<std::uint32_t>(q[3]) << 24);
#endif
  }
};

// The word rgba() returns, from four channel values.
constexpr std::uint32_t pack_rgba(std::uint32_t r, std::uint32_t g, std::uint32_t b, std::uint32_t a) {
  return (r & 0xFF) | ((g & 0xFF) << 8) | ((b & 0xFF) << 16) | (a << 24);
}

// Stores an rgba() word as the four bytes R, G, B, A of an RGBA8888 pixel.
[[gnu::always_inline]] inline void store_rgba(std::uint8_t* p, std::uint32_t c) {
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(p, &c, 4);
  } else {
    p[0] = static_cast<std::uint8_t>(c);
    p[1] = static_cast<std::uint8_t>(c >> 8);
    p[2] = static_cast<std::uint8_t>(c >> 16);
    p[3] = static_cast<std::uint8_t>(c >> 24);
  }
}

}  // namespace gpubridge::sim
