#pragma once
// Section 10.4's bilinear filter of eight lanes in AVX-512's 16-bit lanes, shared by the exact
// span routine's AVX-512 instances (texture8.hpp, through texture8_wide.hpp) and the preview's
// AVX-512 instance (preview_plain_kernel.inc's combine_texels): both filter with the same integers,
// and this form is about half the vector instructions of the 32-bit one (docs/simulator.md,
// sim-tex8 and sim-ptex). Only code compiled for AVX-512 (VL, BW, DQ) may call it.
#include <immintrin.h>

#include <cstring>

#include "simd_lanes.hpp"

namespace gpubridge::sim {

#define BILINEAR_WIDE_TARGET __attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq")))

// Section 10.4's bilinear filter of eight lanes in 16-bit lanes: the same integers as
// filter_combine8's (t00·(256−u)(256−v) + t10·u(256−v) + t01·(256−u)v + t11·uv + 2^15) >> 16 per
// channel, summed as (256−v)·A + v·B with A = (256−u)·t00 + u·t10 and B = (256−u)·t01 + u·t11
// (the same sum regrouped). A and B are below 2^16 (at most 256·255), so each is one 16-bit
// multiply-low pair (vpmullw) and exact; the outer sum is one vpmaddwd of the words (A − 2^15,
// B − 2^15), signed, with the words (256 − v, v), and 2^23 added back. A chunk is about 35 vector
// instructions where the 32-bit form's four channels of four multiplies are about 75. Vectors go by
// pointer and to and from memory by memcpy (texture8_wide.hpp's head says why). u, v in 0..255.
BILINEAR_WIDE_TARGET inline void bilinear_filter_wide(const simd::u32x8* t00, const simd::u32x8* t10,
                                                      const simd::u32x8* t01, const simd::u32x8* t11,
                                                      const simd::u32x8* u, const simd::u32x8* v, simd::u32x8* out) {
  __m256i a00, a10, a01, a11, uu, vv;
  std::memcpy(&a00, t00, 32);
  std::memcpy(&a10, t10, 32);
  std::memcpy(&a01, t01, 32);
  std::memcpy(&a11, t11, 32);
  std::memcpy(&uu, u, 32);
  std::memcpy(&vv, v, 32);
  // Bytes of the two rows interleaved and widened: 32-bit lane 4p + c of `lo` holds the words
  // (t00, t01) of channel c of pixel 0, 1, 4, 5 (p = 0..3; the 256-bit unpacks work per 128-bit
  // half), `hi` of pixels 2, 3, 6, 7; x for the left column, y for the right.
  const __m512i x_lo = _mm512_cvtepu8_epi16(_mm256_unpacklo_epi8(a00, a01));
  const __m512i x_hi = _mm512_cvtepu8_epi16(_mm256_unpackhi_epi8(a00, a01));
  const __m512i y_lo = _mm512_cvtepu8_epi16(_mm256_unpacklo_epi8(a10, a11));
  const __m512i y_hi = _mm512_cvtepu8_epi16(_mm256_unpackhi_epi8(a10, a11));
  // Each pixel's weights to its four channels' lanes in the same pixel order: (u, u) and
  // (256 − v, v) as word pairs. (The maskz forms: GCC 12's unmasked 512-bit intrinsics trip
  // -Wmaybe-uninitialized on their undefined pass-through operands.)
  const __m256i u2 = _mm256_or_si256(uu, _mm256_slli_epi32(uu, 16));
  const __m256i v2 = _mm256_or_si256(_mm256_sub_epi32(_mm256_set1_epi32(256), vv), _mm256_slli_epi32(vv, 16));
  const __m512i pick_lo = _mm512_set_epi32(5, 5, 5, 5, 4, 4, 4, 4, 1, 1, 1, 1, 0, 0, 0, 0);
  const __m512i pick_hi = _mm512_set_epi32(7, 7, 7, 7, 6, 6, 6, 6, 3, 3, 3, 3, 2, 2, 2, 2);
  const __m512i u_lo = _mm512_maskz_permutexvar_epi32(0xFFFF, pick_lo, _mm512_castsi256_si512(u2));
  const __m512i u_hi = _mm512_maskz_permutexvar_epi32(0xFFFF, pick_hi, _mm512_castsi256_si512(u2));
  const __m512i v_lo = _mm512_maskz_permutexvar_epi32(0xFFFF, pick_lo, _mm512_castsi256_si512(v2));
  const __m512i v_hi = _mm512_maskz_permutexvar_epi32(0xFFFF, pick_hi, _mm512_castsi256_si512(v2));
  const __m512i w256 = _mm512_set1_epi16(256), bias = _mm512_set1_epi16(-32768);
  // (A, B) per lane, then (A − 2^15, B − 2^15) as signed words (A, B < 2^16).
  const __m512i ab_lo = _mm512_xor_si512(
      _mm512_add_epi16(_mm512_mullo_epi16(x_lo, _mm512_sub_epi16(w256, u_lo)), _mm512_mullo_epi16(y_lo, u_lo)), bias);
  const __m512i ab_hi = _mm512_xor_si512(
      _mm512_add_epi16(_mm512_mullo_epi16(x_hi, _mm512_sub_epi16(w256, u_hi)), _mm512_mullo_epi16(y_hi, u_hi)), bias);
  // (256 − v)(A − 2^15) + v(B − 2^15) = the sum − 2^23; + 2^23 + 2^15 rounds, >> 16 (sum < 2^24).
  const __m512i round = _mm512_set1_epi32((1 << 23) + 32768);
  const __m512i c_lo = _mm512_maskz_srli_epi32(0xFFFF, _mm512_add_epi32(_mm512_madd_epi16(ab_lo, v_lo), round), 16);
  const __m512i c_hi = _mm512_maskz_srli_epi32(0xFFFF, _mm512_add_epi32(_mm512_madd_epi16(ab_hi, v_hi), round), 16);
  // Back to bytes in pixel order: the in-half pack puts pixels 0, 2 | 1, 3 | 4, 6 | 5, 7 in the
  // four 128-bit quarters (four words each), the narrowing keeps that order in 32-bit lanes, and
  // one in-half dword shuffle (0, 2, 1, 3) restores 0..7.
  const __m256i bytes = _mm512_maskz_cvtepi16_epi8(~__mmask32{0}, _mm512_packus_epi32(c_lo, c_hi));
  const __m256i texel = _mm256_shuffle_epi32(bytes, 0xD8);
  std::memcpy(out, &texel, 32);
}

}  // namespace gpubridge::sim
