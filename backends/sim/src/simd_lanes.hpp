#pragma once
// 8-lane (and, for the span routine's AVX-512 instance, 16-lane) GCC/Clang vector types and the
// lane operations of the vector routines (span_simd.cpp, narrow_simd.cpp). The lane operations are
// templates over the vector type V (u32x8 or u32x16), deduced from their arguments. Every helper is [[gnu::always_inline]]: that is what lets a function compiled
// for the default target inline into the routines' AVX2 target clones (without it GCC keeps a call,
// and a vector argument then crosses it in memory).
#include <bit>
#include <cstdint>
#include <cstring>

#include <immintrin.h>

#include "gpubridge/protocol/registers.hpp"

// Colour words hold channel c in byte c (R lowest), which is memory order R, G, B, A only on a
// little-endian host.
static_assert(std::endian::native == std::endian::little, "the vector routines assume a little-endian host");

namespace gpubridge::sim::simd {

typedef std::uint32_t u32x8 __attribute__((vector_size(32)));
typedef std::int32_t i32x8 __attribute__((vector_size(32)));
typedef std::uint32_t u32x16 __attribute__((vector_size(64)));
typedef std::int32_t i32x16 __attribute__((vector_size(64)));
typedef std::uint32_t u32x4 __attribute__((vector_size(16)));

// The signed lanes of V's width (compares of V give them) and V's lane count.
template <class V>
struct LaneTraits;
template <>
struct LaneTraits<u32x8> {
  using Signed = i32x8;
  static constexpr unsigned kLanes = 8;
};
template <>
struct LaneTraits<u32x16> {
  using Signed = i32x16;
  static constexpr unsigned kLanes = 16;
};
template <class V>
using signed_lanes = typename LaneTraits<V>::Signed;
template <class V>
inline constexpr unsigned kLanesOf = LaneTraits<V>::kLanes;

// A lane compare's result (0 or −1 per lane) as a mask of all-zero / all-one lanes.
[[gnu::always_inline]] inline u32x8 mask(i32x8 m) { return (u32x8)m; }
[[gnu::always_inline]] inline u32x16 mask(i32x16 m) { return (u32x16)m; }

[[gnu::always_inline]] inline u32x8 load8(const void* p) {
  u32x8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::always_inline]] inline void store8(void* p, u32x8 v) { std::memcpy(p, &v, sizeof v); }
template <class V>
[[gnu::always_inline]] inline V load_lanes(const void* p) {
  V v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// The first n (< the lane count) words at p into lanes 0..n-1 of *out, 0 in the rest, and lanes
// 0..n-1 of *v to n words at p: AVX-512's masked moves (the masked-off words are neither read nor
// written, so no fault and no stack copy). Only the AVX-512 instance calls them (kMasked below):
// their target attribute lets them inline there and nowhere else. The vectors go by pointer because
// a vector argument or result between a caller without AVX-512 (load_words / store_words, which are
// inlined into the instance only afterwards) and a callee with it changes the calling convention,
// which clang refuses.
__attribute__((target("avx512f,avx512vl"))) inline void masked_load(const std::uint8_t* p, unsigned n, u32x8* out) {
  *out = (u32x8)_mm256_maskz_loadu_epi32(static_cast<__mmask8>((1u << n) - 1), p);
}
__attribute__((target("avx512f,avx512vl"))) inline void masked_load(const std::uint8_t* p, unsigned n, u32x16* out) {
  *out = (u32x16)_mm512_maskz_loadu_epi32(static_cast<__mmask16>((1u << n) - 1), p);
}
__attribute__((target("avx512f,avx512vl"))) inline void masked_store(std::uint8_t* p, const u32x8* v, unsigned n) {
  _mm256_mask_storeu_epi32(p, static_cast<__mmask8>((1u << n) - 1), (__m256i)*v);
}
__attribute__((target("avx512f,avx512vl"))) inline void masked_store(std::uint8_t* p, const u32x16* v, unsigned n) {
  _mm512_mask_storeu_epi32(p, static_cast<__mmask16>((1u << n) - 1), (__m512i)*v);
}

// Bit k set when lane k of the mask *m (0 or all ones per lane) is set: one vmovmskps. Only the
// instances with AVX2 call it (pixel8's kAvx2); by pointer for the reason given above.
__attribute__((target("avx2"))) inline unsigned lane_bits(const u32x8* m) {
  return static_cast<unsigned>(_mm256_movemask_ps((__m256)*m));
}

// n words from p into lanes 0..n-1; later lanes hold the next words of the row when `whole`
// (eight words fit before the row ends: same row, so the same band and thread) or 0. Both are
// masked off by the caller. Loads straight into the vector where possible: going through a stack
// buffer stores it in pieces and reloads it as one 32-byte word, which defeats store-to-load
// forwarding (a stall per chunk: 30% of random-Z span time for full chunks, and the tail chunk's
// share of the rest).
// kMasked (AVX-512): a tail takes a masked load instead.
template <class V = u32x8, bool kMasked = false>
[[gnu::always_inline]] inline V load_words(const std::uint8_t* p, unsigned n, bool whole) {
  constexpr unsigned kN = kLanesOf<V>;
  if constexpr (kMasked) {
    if (n == kN) return load_lanes<V>(p);
    V v;
    masked_load(p, n, &v);
    return v;
  } else {
    if (n == kN || whole) return load_lanes<V>(p);
    std::uint32_t buf[kN] = {};
    std::memcpy(buf, p, std::size_t{n} * 4);
    return load_lanes<V>(buf);
  }
}
// Lanes 0..n-1 to n words at p. Full chunks copy a constant 32 bytes (inlined); only the tail
// copies n words (kMasked: a masked store), eight lanes' tails in pieces of 4, 2 and 1 words with
// constant sizes (inlined: a copy of n words was a call to memcpy, its vector spilled around it).
template <bool kMasked = false, class V>
[[gnu::always_inline]] inline void store_words(std::uint8_t* p, V v, unsigned n) {
  if (n == kLanesOf<V>) {
    std::memcpy(p, &v, sizeof v);
  } else if constexpr (kMasked) {
    masked_store(p, &v, n);
  } else if constexpr (kLanesOf<V> == 8) {
    u32x4 part = __builtin_shufflevector(v, v, 0, 1, 2, 3);
    if (n & 4) {
      std::memcpy(p, &part, 16);
      part = __builtin_shufflevector(v, v, 4, 5, 6, 7);
      p += 16;
    }
    if (n & 2) {
      std::memcpy(p, &part, 8);
      part = __builtin_shufflevector(part, part, 2, 3, 2, 3);
      p += 8;
    }
    if (n & 1) std::memcpy(p, &part, 4);
  } else {
    std::memcpy(p, &v, std::size_t{n} * 4);
  }
}

typedef std::uint8_t u8x32 __attribute__((vector_size(32)));
typedef std::uint8_t u8x64 __attribute__((vector_size(64)));

// Z is stored big-endian in video memory (docs/protocol.md): byte-swap each lane. kShuffle (the
// instances with AVX2 or AVX-512BW): one byte shuffle (vpshufb), as the preview kernel does, for
// the nine shifts, masks and ors; without it (baseline x86-64, which has no byte shuffle, where
// GCC spells a generic shuffle byte by byte through the stack) the shifts.
#define GPUBRIDGE_BSWAP4(b) b + 3, b + 2, b + 1, b
#define GPUBRIDGE_BSWAP16(b) GPUBRIDGE_BSWAP4(b), GPUBRIDGE_BSWAP4(b + 4), GPUBRIDGE_BSWAP4(b + 8), GPUBRIDGE_BSWAP4(b + 12)
template <bool kShuffle = false, class V>
[[gnu::always_inline]] inline V bswap(V w) {
  if constexpr (kShuffle && kLanesOf<V> == 8) {
    return (V)__builtin_shufflevector((u8x32)w, (u8x32)w, GPUBRIDGE_BSWAP16(0), GPUBRIDGE_BSWAP16(16));
  } else if constexpr (kShuffle) {
    return (V)__builtin_shufflevector((u8x64)w, (u8x64)w, GPUBRIDGE_BSWAP16(0), GPUBRIDGE_BSWAP16(16),
                                      GPUBRIDGE_BSWAP16(32), GPUBRIDGE_BSWAP16(48));
  } else {
    return (w >> 24) | ((w >> 8) & 0xFF00u) | ((w << 8) & 0xFF0000u) | (w << 24);
  }
}
#undef GPUBRIDGE_BSWAP16
#undef GPUBRIDGE_BSWAP4

// The sum of the lanes (each lane's count of passes: the total stays far below 2^32), halves
// folded onto each other: a few adds and shuffles where eight extracts and 64-bit adds were.
[[gnu::always_inline]] inline std::uint32_t lane_sum(u32x8 v) {
  u32x4 a = __builtin_shufflevector(v, v, 0, 1, 2, 3) + __builtin_shufflevector(v, v, 4, 5, 6, 7);
  a += __builtin_shufflevector(a, a, 2, 3, 0, 1);
  a += __builtin_shufflevector(a, a, 1, 0, 3, 2);
  return a[0];
}
[[gnu::always_inline]] inline std::uint32_t lane_sum(u32x16 v) {
  return lane_sum(u32x8(__builtin_shufflevector(v, v, 0, 1, 2, 3, 4, 5, 6, 7) +
                        __builtin_shufflevector(v, v, 8, 9, 10, 11, 12, 13, 14, 15)));
}

// One carry of an exact (q, r) stepper: r < 2·den < 2^31 before, r < den after (the signed
// compare is exact); q counts the carry (carry lanes are all ones, −1).
template <class V>
[[gnu::always_inline]] inline void carry(V& q, V& r, V den) {
  using S = signed_lanes<V>;
  const V c = mask((S)r >= (S)den);
  r -= den & c;
  q -= c;
}

// `pass` narrowed to the lanes whose new depth z passes the test `f` against the stored depth d
// (TRI_MODE.Z_FUNC), both < 2^24 in signed lanes.
template <class V>
[[gnu::always_inline]] inline V depth_test(protocol::DepthFunc f, V pass, signed_lanes<V> z, signed_lanes<V> d) {
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
  return V{};
}

// div255 of fixed_point.hpp in lanes: round(x / 255) for 0 <= x <= 65025.
template <class V>
[[gnu::always_inline]] inline V div255(V x) { return (x + 128u + ((x + 128u) >> 8)) >> 8; }

// Section 11's blend (`mode` ALPHA, ADD or MULTIPLY) of eight source words with the eight stored
// ones (byte c of a word is channel c: R, G, B, A), channel by channel in 32-bit lanes.
template <class V>
[[gnu::always_inline]] inline V blend(protocol::BlendMode mode, V src, V dst) {
  const V a = src >> 24, inv = 255u - a;
  V out = {};
  for (unsigned c = 0; c < 32; c += 8) {
    const V s = (src >> c) & 255u, d = (dst >> c) & 255u;
    V v;
    if (mode == protocol::BlendMode::Alpha) {
      v = div255(s * a + d * inv);
    } else if (mode == protocol::BlendMode::Add) {
      v = s + d;
      const V over = mask((signed_lanes<V>)v > 255);
      v = (v & ~over) | (255u & over);
    } else {
      v = div255(s * d);
    }
    out |= v << c;
  }
  return out;
}

}  // namespace gpubridge::sim::simd
