#pragma once
// 8-lane GCC/Clang vector types and the lane operations of the vector routines (span_simd.cpp,
// narrow_simd.cpp). Every helper is [[gnu::always_inline]]: that is what lets a function compiled
// for the default target inline into the routines' AVX2 target clones (without it GCC keeps a call,
// and a vector argument then crosses it in memory).
#include <bit>
#include <cstdint>
#include <cstring>

#include "gpubridge/protocol/registers.hpp"

// Colour words hold channel c in byte c (R lowest), which is memory order R, G, B, A only on a
// little-endian host.
static_assert(std::endian::native == std::endian::little, "the vector routines assume a little-endian host");

namespace gpubridge::sim::simd {

typedef std::uint32_t u32x8 __attribute__((vector_size(32)));
typedef std::int32_t i32x8 __attribute__((vector_size(32)));

// A lane compare's result (0 or −1 per lane) as a mask of all-zero / all-one lanes.
[[gnu::always_inline]] inline u32x8 mask(i32x8 m) { return (u32x8)m; }

[[gnu::always_inline]] inline u32x8 load8(const void* p) {
  u32x8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::always_inline]] inline void store8(void* p, u32x8 v) { std::memcpy(p, &v, sizeof v); }

// n words from p into lanes 0..n-1; later lanes hold the next words of the row when `whole`
// (eight words fit before the row ends: same row, so the same band and thread) or 0. Both are
// masked off by the caller. Loads straight into the vector where possible: going through a stack
// buffer stores it in pieces and reloads it as one 32-byte word, which defeats store-to-load
// forwarding (a stall per chunk: 30% of random-Z span time for full chunks, and the tail chunk's
// share of the rest).
[[gnu::always_inline]] inline u32x8 load_words(const std::uint8_t* p, unsigned n, bool whole) {
  if (n == 8 || whole) return load8(p);
  std::uint32_t buf[8] = {};
  std::memcpy(buf, p, std::size_t{n} * 4);
  return load8(buf);
}
// Lanes 0..n-1 to n words at p. Full chunks copy a constant 32 bytes (inlined); only the tail
// copies n words.
[[gnu::always_inline]] inline void store_words(std::uint8_t* p, u32x8 v, unsigned n) {
  if (n == 8) std::memcpy(p, &v, 32);
  else std::memcpy(p, &v, std::size_t{n} * 4);
}

// Z is stored big-endian in video memory (docs/protocol.md): byte-swap each lane.
[[gnu::always_inline]] inline u32x8 bswap(u32x8 w) {
  return (w >> 24) | ((w >> 8) & 0xFF00u) | ((w << 8) & 0xFF0000u) | (w << 24);
}

// One carry of an exact (q, r) stepper: r < 2·den < 2^31 before, r < den after (the signed
// compare is exact); q counts the carry (carry lanes are all ones, −1).
[[gnu::always_inline]] inline void carry(u32x8& q, u32x8& r, u32x8 den) {
  const u32x8 c = mask((i32x8)r >= (i32x8)den);
  r -= den & c;
  q -= c;
}

// `pass` narrowed to the lanes whose new depth z passes the test `f` against the stored depth d
// (TRI_MODE.Z_FUNC), both < 2^24 in signed lanes.
[[gnu::always_inline]] inline u32x8 depth_test(protocol::DepthFunc f, u32x8 pass, i32x8 z, i32x8 d) {
  using protocol::DepthFunc;
  switch (f) {
    case DepthFunc::Less: return pass & mask(z < d);
    case DepthFunc::Equal: return pass & mask(z == d);
    case DepthFunc::LessEqual: return pass & mask(z <= d);
    case DepthFunc::Greater: return pass & mask(z > d);
    case DepthFunc::NotEqual: return pass & mask(z != d);
    case DepthFunc::GreaterEqual: return pass & mask(z >= d);
    case DepthFunc::Always: return pass;
    case DepthFunc::Never: break;
  }
  return u32x8{};
}

// div255 of fixed_point.hpp in lanes: round(x / 255) for 0 <= x <= 65025.
[[gnu::always_inline]] inline u32x8 div255(u32x8 x) { return (x + 128u + ((x + 128u) >> 8)) >> 8; }

// Section 11's blend (`mode` ALPHA, ADD or MULTIPLY) of eight source words with the eight stored
// ones (byte c of a word is channel c: R, G, B, A), channel by channel in 32-bit lanes.
[[gnu::always_inline]] inline u32x8 blend(protocol::BlendMode mode, u32x8 src, u32x8 dst) {
  const u32x8 a = src >> 24, inv = 255u - a;
  u32x8 out = {};
  for (unsigned c = 0; c < 32; c += 8) {
    const u32x8 s = (src >> c) & 255u, d = (dst >> c) & 255u;
    u32x8 v;
    if (mode == protocol::BlendMode::Alpha) {
      v = div255(s * a + d * inv);
    } else if (mode == protocol::BlendMode::Add) {
      v = s + d;
      const u32x8 over = mask((i32x8)v > 255);
      v = (v & ~over) | (255u & over);
    } else {
      v = div255(s * d);
    }
    out |= v << c;
  }
  return out;
}

}  // namespace gpubridge::sim::simd
