#pragma once
// The texture stage of the vector routines for eight lanes (called by pixel8.hpp). Internal to
// those routines' .cpp files: it is inlined into their target clones.
#include "simd_lanes.hpp"
#include "texture.hpp"
#include "texture_lanes.hpp"
#include "texture8_wide.hpp"

namespace gpubridge::sim {

// Section 10.4's bilinear filter (nearest: t00 as it is) and 10.5's combine with the vertex colour
// `color` of eight lanes whose texels are fetched. Returns the combined words. kWide (the span
// routine's AVX-512 instances): the filter in 16-bit lanes (bilinear_filter_wide, the same integers).
template <bool kWide = false>
[[gnu::always_inline]] inline simd::u32x8 filter_combine8(const TextureLanes& s, simd::u32x8 t00, simd::u32x8 t10,
                                                          simd::u32x8 t01, simd::u32x8 t11, simd::u32x8 u,
                                                          simd::u32x8 v, simd::u32x8 color) {
  using simd::u32x8;
  u32x8 texel = t00;
  if constexpr (kWide) {
    if (s.tex->bilinear()) bilinear_filter_wide(&t00, &t10, &t01, &t11, &u, &v, &texel);
  } else if (s.tex->bilinear()) {
    const u32x8 w00 = (256u - u) * (256u - v), w10 = u * (256u - v), w01 = (256u - u) * v, w11 = u * v;
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

// The filter and combine of eight lanes whose texel coordinates are known (tc[k] for k < n):
// lanes that passed the depth test get their addressed neighbours one by one, then the bilinear
// filter and the combine with the vertex colour `color` run in lanes. Returns the combined words.
template <bool kWide = false>
[[gnu::always_inline]] inline simd::u32x8 texture8_sample(const TextureLanes& s, const TexelCoords* tc, simd::u32x8 pass,
                                                          unsigned n, simd::u32x8 color) {
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
  return filter_combine8<kWide>(s, simd::load8(c00), simd::load8(c10), simd::load8(c01), simd::load8(c11),
                                simd::load8(fu), simd::load8(fv), color);
}

// The texture stage for eight pixels (section 10): texel coordinates of every lane from the exact
// (s, t, q) planes through the reciprocal unit, then texture8_sample.
// kWide (the span routine's AVX-512 instances): perspective triangles on an RGBA8888 bilinear repeat
// texture take texel_quads_wide instead, the same texels and fractions from lanes throughout.
template <bool kWide = false>
[[gnu::always_inline]] inline simd::u32x8 texture8(const TextureLanes& s, simd::u32x8 sq, simd::u32x8 tq,
                                                   simd::u32x8 qq, simd::u32x8 pass, unsigned n, simd::u32x8 color) {
  if constexpr (kWide) {
    if (!s.q_const && s.tex->bilinear_rgba_repeat()) {
      // Lanes beyond n hold the planes' next pixels, not this span's: never fetched.
      const simd::i32x8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
      const simd::u32x8 ok = pass & simd::mask(lane < static_cast<std::int32_t>(n));
      TexQuad8 t;
      texel_quads_wide(s, &sq, &tq, &qq, &ok, &t);
      return filter_combine8<true>(s, t.t00, t.t10, t.t01, t.t11, t.fu, t.fv, color);
    }
  }
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
  return texture8_sample<kWide>(s, tc, pass, n, color);
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
