#pragma once
// 8-lane GCC/Clang vector types and the helpers both SIMD routines (span_simd.cpp, narrow_simd.cpp)
// share. The helpers are macros, not functions, so that they inline into every target clone (a
// plain inline function compiled for the default target would not inline into the AVX2 clone).
#include <bit>
#include <cstdint>
#include <cstring>

// Colour words hold channel c in byte c (R lowest), which is memory order R, G, B, A only on a
// little-endian host.
static_assert(std::endian::native == std::endian::little, "the vector routines assume a little-endian host");

namespace gpubridge::sim::simd {
typedef std::uint32_t u32x8 __attribute__((vector_size(32)));
typedef std::int32_t i32x8 __attribute__((vector_size(32)));
}  // namespace gpubridge::sim::simd

#define GB_LOAD8(dst, p) std::memcpy(&(dst), (p), sizeof(u32x8))
#define GB_STORE8(p, src) std::memcpy((p), &(src), sizeof(u32x8))
// Z is stored big-endian in video memory (docs/protocol.md): byte-swap each lane.
#define GB_BSWAP(w) (((w) >> 24) | (((w) >> 8) & 0xFF00u) | (((w) << 8) & 0xFF0000u) | ((w) << 24))
#define GB_MASK(m) ((u32x8)(m))
// pass &= the depth test `func` (TRI_MODE.Z_FUNC: 0 NEVER, 1 LESS, 2 EQUAL, 3 LEQUAL, 4 GREATER,
// 5 NOTEQUAL, 6 GEQUAL, 7 ALWAYS) of new depth zi against stored di, both < 2^24 in signed lanes.
#define GB_DEPTH_TEST(pass, zi, di, func)           \
  do {                                              \
    switch (func) {                                 \
      case 1: (pass) &= GB_MASK((zi) < (di)); break;  \
      case 2: (pass) &= GB_MASK((zi) == (di)); break; \
      case 3: (pass) &= GB_MASK((zi) <= (di)); break; \
      case 4: (pass) &= GB_MASK((zi) > (di)); break;  \
      case 5: (pass) &= GB_MASK((zi) != (di)); break; \
      case 6: (pass) &= GB_MASK((zi) >= (di)); break; \
      case 7: break;                                \
      default: (pass) = u32x8{}; break;             \
    }                                               \
  } while (0)

// Section 11's blend of eight source words with the eight stored ones (byte c of a word is channel
// c: R, G, B, A), channel by channel in 32-bit lanes; div255 as in fixed_point.hpp. Mode is
// protocol::BlendMode (1 ALPHA, 2 ADD, 3 MULTIPLY).
#define GB_DIV255(x) (((x) + 128u + (((x) + 128u) >> 8)) >> 8)
#define GB_BLEND8(mode, src, dst)                                                    \
  ({                                                                                 \
    const u32x8 bl_a = (src) >> 24, bl_inv = 255u - bl_a;                            \
    u32x8 bl_out = {};                                                               \
    for (unsigned bl_c = 0; bl_c < 32; bl_c += 8) {                                  \
      const u32x8 bl_s = ((src) >> bl_c) & 255u, bl_d = ((dst) >> bl_c) & 255u;      \
      u32x8 bl_v;                                                                    \
      if ((mode) == 1) {                                                             \
        bl_v = bl_s * bl_a + bl_d * bl_inv;                                          \
        bl_v = GB_DIV255(bl_v);                                                      \
      } else if ((mode) == 2) {                                                      \
        bl_v = bl_s + bl_d;                                                          \
        const u32x8 bl_over = GB_MASK((i32x8)bl_v > 255);                            \
        bl_v = (bl_v & ~bl_over) | (255u & bl_over);                                 \
      } else {                                                                       \
        bl_v = bl_s * bl_d;                                                          \
        bl_v = GB_DIV255(bl_v);                                                      \
      }                                                                              \
      bl_out |= bl_v << bl_c;                                                        \
    }                                                                                \
    bl_out;                                                                          \
  })
