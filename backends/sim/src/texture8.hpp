#pragma once
// The texture stage of the vector routines for eight lanes (called by pixel8.hpp). Internal to
// those routines' .cpp files: it is inlined into their target clones.
#include "simd_lanes.hpp"
#include "texture.hpp"
#include "texture_lanes.hpp"

namespace gpubridge::sim {

// The filter and combine of eight lanes whose texel coordinates are known (tc[k] for k < n):
// lanes that passed the depth test get their addressed neighbours one by one, then the bilinear
// filter and the combine with the vertex colour `color` run in lanes. Returns the combined words.
[[gnu::always_inline]] inline simd::u32x8 texture8_sample(const TextureLanes& s, const TexelCoords* tc, simd::u32x8 pass,
                                                          unsigned n, simd::u32x8 color) {
  using simd::u32x8;
  std::uint32_t pv[8];
  simd::store8(pv, pass);
  alignas(32) std::uint32_t c00[8] = {}, c10[8] = {}, c01[8] = {}, c11[8] = {}, fu[8] = {}, fv[8] = {};
  for (unsigned k = 0; k < n; ++k)
    if (pv[k]) s.tex->quad(tc[k], c00[k], c10[k], c01[k], c11[k], fu[k], fv[k]);  // rejected lanes: never sampled
  u32x8 texel = simd::load8(c00);
  if (s.tex->bilinear()) {
    const u32x8 t10 = simd::load8(c10), t01 = simd::load8(c01), t11 = simd::load8(c11);
    const u32x8 u = simd::load8(fu), v = simd::load8(fv);
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

// Sections 10.1 and 10.2 for eight lanes at once, in four 64-bit lanes at a time: the reciprocal
// unit (ReciprocalUnit::operator()) and texel_coords of every lane, integer-exact, so the same
// values as the scalar functions (q = 0 gives (0, 0)). Scalar per lane, the leading-zero count,
// the table read, the Newton-Raphson step's 128-bit multiply and the two shifted products were
// the largest share of the perspective road's span time (perf) after its texel loads.
[[gnu::always_inline]] inline void texel_coords8(const ReciprocalUnit& recip, const std::uint32_t* sv,
                                                 const std::uint32_t* tv, const std::uint32_t* qv, unsigned wl,
                                                 unsigned hl, TexelCoords* tc) {
  using u64x4 = std::uint64_t __attribute__((vector_size(32)));
  using i64x4 = std::int64_t __attribute__((vector_size(32)));
  using f64x4 = double __attribute__((vector_size(32)));
  const std::uint32_t* table = recip.table();
  const unsigned bits = recip.table_bits(), steps = recip.nr_steps();
  const u64x4 index_mask = u64x4{} + ((std::uint64_t{1} << bits) - 1);
  for (unsigned h = 0; h < 8; h += 4) {
    const u64x4 q = {qv[h], qv[h + 1], qv[h + 2], qv[h + 3]};
    const i64x4 zero_q = (i64x4)(q == 0);        // all ones where q = 0
    const u64x4 q1 = q | (u64x4)(zero_q & 1);  // q = 0 is computed as q = 1, then zeroed
    // floor(log2 q1) from the exponent of the exact double 2^52 + q1 minus 2^52.
    const u64x4 magic = u64x4{} + 0x4330000000000000ull;
    f64x4 d;
    const u64x4 qm = q1 | magic;
    std::memcpy(&d, &qm, sizeof d);
    d -= f64x4{} + 4503599627370496.0;  // 2^52
    u64x4 e;
    std::memcpy(&e, &d, sizeof e);
    const u64x4 lz = 31u - ((e >> 52) - 1023u);  // leading zeros of the 32-bit q1
    const u64x4 m = q1 << lz;                    // 2^31 <= m < 2^32
    const u64x4 idx = (m >> (31u - bits)) & index_mask;
    u64x4 y = {table[idx[0]], table[idx[1]], table[idx[2]], table[idx[3]]};
    for (unsigned k = 0; k < steps; ++k) {
      const u64x4 p = m * y;              // < 2^64
      const u64x4 t = (0u - p) >> 32;     // u1.31
      const u64x4 yt = (y * t) >> 31;     // y, t < 2^32: the product fits 64 bits
      const u64x4 over = (u64x4)(yt > 0xFFFFFFFFu);
      y = (yt & ~over) | (0xFFFFFFFFu & over);
    }
    // (s · y) >> (43 − n − wl), arithmetic: a logical shift of the value with its sign folded in.
    auto product_shift = [&](const std::uint32_t* a, unsigned log2) {
      const i64x4 v = {static_cast<std::int32_t>(a[h]), static_cast<std::int32_t>(a[h + 1]),
                       static_cast<std::int32_t>(a[h + 2]), static_cast<std::int32_t>(a[h + 3])};
      const i64x4 x = v * (i64x4)y;  // |x| < 2^63
      const i64x4 sign = (i64x4)(x < 0);
      const u64x4 shift = (43u - log2) - lz;
      return ((i64x4)(((u64x4)(x ^ sign)) >> shift) ^ sign) & ~zero_q;
    };
    const i64x4 tu = product_shift(sv, wl), tvv = product_shift(tv, hl);
    for (unsigned k = 0; k < 4; ++k) tc[h + k] = {tu[k], tvv[k]};
  }
}

// The texture stage for eight pixels (section 10): texel coordinates of every lane from the exact
// (s, t, q) planes through the reciprocal unit, then texture8_sample.
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
    texel_coords8(*s.recip, sv, tv, qv, s.wl, s.hl, tc);
  }
  return texture8_sample(s, tc, pass, n, color);
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
