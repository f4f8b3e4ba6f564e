#pragma once
// The exact texture stage's reciprocal, texel coordinates, addressing and fetch for eight lanes in
// AVX-512 vectors, for the span routine's AVX-512 instances (texture8.hpp's kWide): perspective
// triangles (Q varies along x) on an RGBA8888 bilinear texture inside VRAM that repeats on both
// axes, the cubes' case. The same integers as ReciprocalUnit::operator(), texel_coords and
// TextureUnit::quad_rgba_repeat lane by lane (docs/simulator.md, sim-cubes): where those are
// dozens of scalar instructions a lane, here a chunk's eight lanes go through one chain of vector
// instructions, and nothing goes back through memory between the reciprocal and the texel loads.
// Also section 10.4's bilinear filter in 16-bit lanes for any bilinear texture of those instances
// (bilinear_wide.hpp: sim-tex8).
// Internal to span_simd.cpp: only its AVX-512 instances call it (the target attribute lets it
// inline there and nowhere else; vectors go by pointer for the reason given at simd_lanes.hpp's
// masked_load, and go to and from memory by memcpy, not simd::load8 / store8: clang refuses a
// vector argument to a function compiled without AVX from one compiled with it).
#include <immintrin.h>

#include <cstdint>
#include <cstring>

#include "bilinear_wide.hpp"
#include "simd_lanes.hpp"
#include "texture.hpp"
#include "texture_lanes.hpp"

namespace gpubridge::sim {

// Four bilinear neighbours of eight lanes as colour words, and the weights' fractions (0..255).
struct TexQuad8 {
  simd::u32x8 t00, t10, t01, t11, fu, fv;
};

#define TEXTURE8_WIDE_TARGET BILINEAR_WIDE_TARGET  // one target list for both headers

// Eight lanes' bilinear footprints: the fractions, the left column a0 (and i0, the unwrapped
// index it came from) and the two rows' first words b0, b1 (word indices into the texture).
struct TexAddress8 {
  simd::u32x8 fu, fv, i0, a0, b0, b1;
};

// Sections 10.1-10.3 for lanes (s, t, q): the same integers as ReciprocalUnit::operator(),
// texel_coords and quad_rgba_repeat's addressing. s.tex->bilinear_rgba_repeat() must hold.
[[gnu::always_inline]] TEXTURE8_WIDE_TARGET inline TexAddress8 texel_address_wide(const TextureLanes& s,
                                                                                  simd::u32x8 sqv, simd::u32x8 tqv,
                                                                                  simd::u32x8 qqv) {
  using simd::u32x8;
  TexAddress8 a;
  const ReciprocalUnit& ru = *s.recip;
  const TextureUnit& tex = *s.tex;
  // Section 10.1 in eight 64-bit lanes. Q = 0 takes the reciprocal of 1 and its lanes' coordinates
  // become (0, 0) below, as in texture8's scalar loop.
  typedef std::uint64_t u64x8 __attribute__((vector_size(64)));
  typedef std::int64_t i64x8 __attribute__((vector_size(64)));
  typedef double f64x8 __attribute__((vector_size(64)));
  // Generic vector operations where they compile to one instruction (GCC 12's 512-bit intrinsics
  // trip -Wmaybe-uninitialized on their undefined pass-through operands).
  const __m256i q = (__m256i)qqv;
  const __mmask8 q_nz = _mm256_test_epi32_mask(q, q);
  const u32x8 qn = (u32x8)_mm256_mask_blend_epi32(q_nz, _mm256_set1_epi32(1), q);
  // Leading zeros from the exponent of q as a double (exact: q < 2^53): n = 31 − floor(log2 q).
  const u64x8 n = (1023 + 31) - ((u64x8)__builtin_convertvector(qn, f64x8) >> 52);
  const u64x8 m = __builtin_convertvector(qn, u64x8) << n;  // 2^31 <= m < 2^32
  const unsigned b = ru.table_bits();
  const u64x8 idx = (m >> (31 - b)) & ((std::uint64_t{1} << b) - 1);
  // The table's word computed rather than looked up (the gather's latency showed in the profile of
  // a texture that never misses): reciprocal.cpp's y = floor((2^(b+34) + den) / (2·den)),
  // den = 2^(b+1) + 2i + 1, in doubles. Exact: numerator and divisor are integers below 2^53; a
  // quotient below 2^32 is rounded by less than 2^-21, and a non-integer one lies at least
  // 1/(2·den) > 2^-19 (b <= 16) from the integers, so truncating the rounded quotient gives the
  // floor. (The knobs allow b <= 16; a unit built with a larger table reads it, one gather a chunk.)
  u64x8 y;
  if (b <= 16) {
    const u64x8 den = 2 * idx + ((std::uint64_t{1} << (b + 1)) + 1);
    const f64x8 num = __builtin_convertvector(den, f64x8) + static_cast<double>(std::uint64_t{1} << (b + 34));
    y = __builtin_convertvector(num / __builtin_convertvector(2 * den, f64x8), u64x8);
  } else {
    y = __builtin_convertvector(
        (u32x8)_mm512_mask_i64gather_epi32(_mm256_setzero_si256(), 0xFF, (__m512i)idx, ru.table(), 4), u64x8);
  }
  for (unsigned k = 0; k < ru.nr_steps(); ++k) {
    // m and y < 2^32: vpmuludq's 32 × 32 → 64-bit products are operator()'s 64-bit ones.
    const u64x8 p = (u64x8)_mm512_maskz_mul_epu32(0xFF, (__m512i)m, (__m512i)y);
    const u64x8 t = (0 - p) >> 32;
    const u64x8 yt = (u64x8)_mm512_maskz_mul_epu32(0xFF, (__m512i)y, (__m512i)t) >> 31;
    y = yt > 0xFFFFFFFFu ? u64x8{} + 0xFFFFFFFFu : yt;
  }
  // Section 10.2: (s · y) >> (43 − n − log2 size), signed 64-bit (|s · y| < 2^63), then only the
  // low 32 bits: the repeat masks and fractions read bits 4..21 (sizes <= 2^10).
  const i64x8 sy = __builtin_convertvector((simd::i32x8)sqv, i64x8) * (i64x8)y;
  const i64x8 ty = __builtin_convertvector((simd::i32x8)tqv, i64x8) * (i64x8)y;
  const i64x8 tu = sy >> (i64x8)((43 - s.wl) - n), tv = ty >> (i64x8)((43 - s.hl) - n);
  // quad_rgba_repeat in 32-bit lanes (mod 2^32, the same bits).
  const u32x8 uu = (u32x8)_mm512_maskz_cvtepi64_epi32(q_nz, (__m512i)tu) - 2048u;
  const u32x8 vv = (u32x8)_mm512_maskz_cvtepi64_epi32(q_nz, (__m512i)tv) - 2048u;
  a.fu = (uu >> 4) & 255u;
  a.fv = (vv >> 4) & 255u;
  const std::uint32_t wm = tex.wmask(), hm = tex.hmask();
  const unsigned wl = tex.wl();
  const u32x8 i0 = uu >> 12, j0 = vv >> 12;
  const u32x8 a0 = i0 & wm;
  const u32x8 b0 = (j0 & hm) << wl, b1 = ((j0 + 1u) & hm) << wl;
  a.i0 = i0;
  a.a0 = a0;
  a.b0 = b0;
  a.b1 = b1;
  return a;
}

// Lanes k in `pass` (all ones or zero; rejected lanes and lanes beyond the span are 0) get their
// texels; the other lanes' words are unspecified (the caller's blend and stores mask them off).
// s.tex->bilinear_rgba_repeat() must hold and s.q_const must not.
TEXTURE8_WIDE_TARGET inline void texel_quads_wide(const TextureLanes& s, const simd::u32x8* sq, const simd::u32x8* tq,
                                                  const simd::u32x8* qq, const simd::u32x8* pass, TexQuad8* out) {
  using simd::u32x8;
  const TexAddress8 a = texel_address_wide(s, *sq, *tq, *qq);
  out->fu = a.fu;
  out->fv = a.fv;
  const TextureUnit& tex = *s.tex;
  const std::uint32_t wm = tex.wmask();
  const u32x8 i0 = a.i0, a0 = a.a0, b0 = a.b0, b1 = a.b1;
  const u32x8 ok = *pass;
  const std::uint8_t* texels = tex.texels();
  // A passing lane's two columns are words a0 and a0 + 1 of their rows unless a0 is the last
  // column (the repeat's seam: a1 = 0): then the chunk loads word by word. Rejected lanes load
  // the texture's first pair (index 0), which is in every row's bounds and stays cached.
  const __mmask8 seam = _mm256_mask_cmpeq_epi32_mask(_mm256_movepi32_mask((__m256i)ok), (__m256i)a0,
                                                     _mm256_set1_epi32(static_cast<int>(wm)));
  alignas(32) std::uint32_t at0[8], at1[8];
  if (seam == 0) {
    const u32x8 w0 = (b0 + a0) & ok, w1 = (b1 + a0) & ok;
    std::memcpy(at0, &w0, sizeof w0);
    std::memcpy(at1, &w1, sizeof w1);
    const auto pair = [&](const std::uint32_t* at, unsigned k) __attribute__((always_inline)) {
      std::uint64_t w;
      std::memcpy(&w, texels + std::size_t{at[k]} * 4, 8);
      return static_cast<long long>(w);
    };
    // Lanes 0 1 4 5 and 2 3 6 7 of each row's pairs: one in-lane shuffle (vshufps) each puts the
    // words in lane order (preview_plain_kernel.inc's fetch_pairs).
    const __m256 r0a = (__m256)_mm256_set_epi64x(pair(at0, 5), pair(at0, 4), pair(at0, 1), pair(at0, 0));
    const __m256 r0b = (__m256)_mm256_set_epi64x(pair(at0, 7), pair(at0, 6), pair(at0, 3), pair(at0, 2));
    const __m256 r1a = (__m256)_mm256_set_epi64x(pair(at1, 5), pair(at1, 4), pair(at1, 1), pair(at1, 0));
    const __m256 r1b = (__m256)_mm256_set_epi64x(pair(at1, 7), pair(at1, 6), pair(at1, 3), pair(at1, 2));
    out->t00 = (u32x8)_mm256_shuffle_ps(r0a, r0b, 0x88);
    out->t10 = (u32x8)_mm256_shuffle_ps(r0a, r0b, 0xDD);
    out->t01 = (u32x8)_mm256_shuffle_ps(r1a, r1b, 0x88);
    out->t11 = (u32x8)_mm256_shuffle_ps(r1a, r1b, 0xDD);
    return;
  }
  const u32x8 a1 = (i0 + 1u) & wm;
  alignas(32) std::uint32_t c0[8], c1[8], w[4][8] = {};
  std::memcpy(at0, &b0, sizeof b0);
  std::memcpy(at1, &b1, sizeof b1);
  std::memcpy(c0, &a0, sizeof a0);
  std::memcpy(c1, &a1, sizeof a1);
  for (unsigned k = 0; k < 8; ++k) {
    if (!ok[k]) continue;
    std::memcpy(&w[0][k], texels + (std::size_t{at0[k]} + c0[k]) * 4, 4);
    std::memcpy(&w[1][k], texels + (std::size_t{at0[k]} + c1[k]) * 4, 4);
    std::memcpy(&w[2][k], texels + (std::size_t{at1[k]} + c0[k]) * 4, 4);
    std::memcpy(&w[3][k], texels + (std::size_t{at1[k]} + c1[k]) * 4, 4);
  }
  std::memcpy(&out->t00, w[0], sizeof out->t00);
  std::memcpy(&out->t10, w[1], sizeof out->t10);
  std::memcpy(&out->t01, w[2], sizeof out->t01);
  std::memcpy(&out->t11, w[3], sizeof out->t11);
}

}  // namespace gpubridge::sim
