#pragma once
// The texture stage of the vector routines for eight lanes (called by pixel8.hpp). Internal to
// those routines' .cpp files: it is inlined into their target clones.
#include "simd_lanes.hpp"
#include "texture.hpp"
#include "texture_lanes.hpp"

namespace gpubridge::sim {

// Eight texel words at word indices *idx from base, lanes whose *mask is 0 left 0 and not read: one
// vpgatherdd. Only the instances with AVX2 call it (texture8_sample's kGather); the vectors go by
// pointer for the calling-convention reason given at simd_lanes.hpp's masked_load.
__attribute__((target("avx2"))) inline void gather_words(const std::uint8_t* base, const simd::u32x8* idx,
                                                         const simd::u32x8* mask, simd::u32x8* out) {
  *out = (simd::u32x8)_mm256_mask_i32gather_epi32(_mm256_setzero_si256(), reinterpret_cast<const int*>(base),
                                                  (__m256i)*idx, (__m256i)*mask, 4);
}

// The filter and combine of eight lanes whose texel coordinates are known (tc[k] for k < n):
// lanes that passed the depth test get their addressed neighbours one by one, then the bilinear
// filter and the combine with the vertex colour `color` run in lanes. Returns the combined words.
// kGather (instances with AVX2): an RGBA8888 bilinear repeat texture's four corners by gathers,
// addressed in 32-bit lanes: the repeat masks keep bits 12..21 of a texel coordinate at most
// (sizes <= 2^10), so its low 32 bits give the same indices and weights as quad_rgba_repeat.
template <bool kGather = false>
[[gnu::always_inline]] inline simd::u32x8 texture8_sample(const TextureLanes& s, const TexelCoords* tc, simd::u32x8 pass,
                                                          unsigned n, simd::u32x8 color) {
  using simd::u32x8;
  u32x8 texel, t10, t01, t11, u, v;
  if (kGather && s.tex->bilinear_rgba_repeat()) {
    alignas(32) std::uint32_t tu[8], tv[8];
    for (unsigned k = 0; k < 8; ++k) {
      tu[k] = static_cast<std::uint32_t>(tc[k].tu);
      tv[k] = static_cast<std::uint32_t>(tc[k].tv);
    }
    const u32x8 uu = simd::load8(tu) - 2048u, vv = simd::load8(tv) - 2048u;
    u = (uu >> 4) & 255u;
    v = (vv >> 4) & 255u;
    const u32x8 i0 = uu >> 12, j0 = vv >> 12;
    const std::uint32_t wm = s.tex->wmask(), hm = s.tex->hmask();
    const unsigned wl = s.tex->wl();
    const u32x8 a0 = i0 & wm, a1 = (i0 + 1u) & wm, b0 = (j0 & hm) << wl, b1 = ((j0 + 1u) & hm) << wl;
    // Rejected lanes and lanes beyond n are not read (0, as the scalar loop leaves them).
    const simd::i32x8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
    const u32x8 mask = pass & simd::mask(lane < static_cast<std::int32_t>(n));
    const std::uint8_t* base = s.tex->texels();
    const u32x8 i00 = a0 + b0, i10 = a1 + b0, i01 = a0 + b1, i11 = a1 + b1;
    gather_words(base, &i00, &mask, &texel);
    gather_words(base, &i10, &mask, &t10);
    gather_words(base, &i01, &mask, &t01);
    gather_words(base, &i11, &mask, &t11);
  } else {
    std::uint32_t pv[8];
    simd::store8(pv, pass);
    alignas(32) std::uint32_t c00[8] = {}, c10[8] = {}, c01[8] = {}, c11[8] = {}, fu[8] = {}, fv[8] = {};
    // Rejected lanes are never sampled. The draw's texture fixes which loop runs (one branch a chunk
    // that always goes the same way within a triangle).
    if (s.tex->bilinear_rgba_repeat()) {
      for (unsigned k = 0; k < n; ++k)
        if (pv[k]) s.tex->quad_rgba_repeat(tc[k], c00[k], c10[k], c01[k], c11[k], fu[k], fv[k]);
    } else {
      for (unsigned k = 0; k < n; ++k)
        if (pv[k]) s.tex->quad(tc[k], c00[k], c10[k], c01[k], c11[k], fu[k], fv[k]);
    }
    texel = simd::load8(c00);
    t10 = simd::load8(c10);
    t01 = simd::load8(c01);
    t11 = simd::load8(c11);
    u = simd::load8(fu);
    v = simd::load8(fv);
  }
  if (s.tex->bilinear()) {
    const u32x8 w00 = (256u - u) * (256u - v), w10 = u * (256u - v), w01 = (256u - u) * v, w11 = u * v;
    const u32x8 t00 = texel;
    texel = u32x8{};
    for (unsigned c = 0; c < 32; c += 8) {  // the weights sum to 2^16: every term stays below 2^24
      const u32x8 sum = ((t00 >> c) & 255u) * w00 + ((t10 >> c) & 255u) * w10 + ((t01 >> c) & 255u) * w01 +
                        ((t11 >> c) & 255u) * w11 + 32768u;
      texel |= (sum >> 16) << c;
    }
  }
  if (s.decal) return texel;
  u32x8 out = {};
  for (unsigned c = 0; c < 32; c += 8) {  // section 10.5 modulate: div255(texel · colour) per channel
    const u32x8 x = ((texel >> c) & 255u) * ((color >> c) & 255u);
    out |= simd::div255(x) << c;
  }
  return out;
}

// The texture stage for eight pixels (section 10): texel coordinates of every lane from the exact
// (s, t, q) planes through the reciprocal unit, then texture8_sample.
template <bool kGather = false>
[[gnu::always_inline]] inline simd::u32x8 texture8(const TextureLanes& s, simd::u32x8 sq, simd::u32x8 tq,
                                                   simd::u32x8 qq, simd::u32x8 pass, unsigned n, simd::u32x8 color) {
  std::uint32_t sv[8], tv[8], qv[8];
  simd::store8(sv, sq);
  simd::store8(tv, tq);
  simd::store8(qv, qq);
  // Texel coordinates of every lane first, in a branch-free loop of independent chains (the
  // reciprocal's multiplies overlap across lanes); q = 0 gives (0, 0) as in the scalar routine.
  TexelCoords tc[8];
  if (s.q_const) {  // the same non-zero Q everywhere: one reciprocal for the triangle
    for (unsigned k = 0; k < n; ++k)
      tc[k] = texel_coords(static_cast<std::int32_t>(sv[k]), static_cast<std::int32_t>(tv[k]), s.const_rc, s.wl, s.hl);
  } else {
    for (unsigned k = 0; k < n; ++k) {
      const std::uint32_t q = qv[k];
      const TexelCoords c = texel_coords(static_cast<std::int32_t>(sv[k]), static_cast<std::int32_t>(tv[k]),
                                         (*s.recip)(q != 0 ? q : 1), s.wl, s.hl);
      tc[k] = q != 0 ? c : TexelCoords{};
    }
  }
  return texture8_sample<kGather>(s, tc, pass, n, color);
}

// The preview path's texture stage: the lanes already hold the texel coordinates (1/4096 texel,
// signed 32-bit; preview_simd.cpp computes them in float).
[[gnu::always_inline]] inline simd::u32x8 texture8_lanes(const TextureLanes& s, simd::u32x8 tu, simd::u32x8 tv,
                                                         simd::u32x8 pass, unsigned n, simd::u32x8 color) {
  TexelCoords tc[8];
  for (unsigned k = 0; k < 8; ++k) tc[k] = {static_cast<std::int32_t>(tu[k]), static_cast<std::int32_t>(tv[k])};
  return texture8_sample(s, tc, pass, n, color);
}


}  // namespace gpubridge::sim
