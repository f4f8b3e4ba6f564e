#include "span_simd.hpp"

#include "packed_lanes.hpp"
#include "simd_lanes.hpp"
#include "texture8.hpp"

namespace gpubridge::sim {
namespace {

using simd::i32x8;
using simd::u32x8;
// Full chunks copy a constant 32 bytes (inlined); only the tail copies n words.
#define GB_COPY(dst, src, n) ((n) == 8 ? std::memcpy((dst), (src), 32) : std::memcpy((dst), (src), (n) * 4))
// n words from memory into lanes 0..n-1; later lanes hold the next words of the row when
// `whole` (eight words fit before the row ends: same row, so the same band and thread) or 0.
// Both are masked off by the caller. Loads straight into the vector where possible: going
// through a stack buffer stores it in pieces and reloads it as one 32-byte word, which defeats
// store-to-load forwarding (a stall per chunk: 30% of random-Z span time for full chunks, and
// the tail chunk's share of the rest).
#define GB_LOAD_N(dst, src, n, whole)                \
  do {                                               \
    if ((n) == 8 || (whole)) {                       \
      GB_LOAD8(dst, src);                            \
    } else {                                         \
      std::uint32_t ln_buf[8] = {};                  \
      std::memcpy(ln_buf, (src), (n) * 4);           \
      GB_LOAD8(dst, ln_buf);                         \
    }                                                \
  } while (0)


}  // namespace

// One instance per plane count, so the plane loops have constant bounds and the lanes stay in
// registers (a run-time bound cost the untextured spans 5-15%).
template <bool kTextured, unsigned kFormat>
[[gnu::always_inline]] inline std::uint64_t shade_span(const SimdSpan& s) {
  constexpr unsigned kBpp = kFormat == 0 ? 4 : kFormat == 1 ? 2 : 1;
  constexpr unsigned kUsed = kTextured ? 8 : 5;
  u32x8 q[kUsed], r[kUsed];
  const unsigned first = s.gouraud ? 0 : 4;
  const u32x8 den = u32x8{} + s.den;
  for (unsigned p = first; p < kUsed; ++p) {
    u32x8 qk, rk;
    GB_LOAD8(qk, s.qk[p]);
    GB_LOAD8(rk, s.rk[p]);
    q[p] = qk + s.q0[p];
    r[p] = rk + s.r0[p];
    const u32x8 carry = GB_MASK((i32x8)r[p] >= (i32x8)den);
    r[p] -= den & carry;
    q[p] -= carry;
  }
  const u32x8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
  const bool depth = s.z_test || s.z_write;
  const bool reads_color = s.blend != 0 || (kFormat == 0 ? s.keep : s.keep_packed) != 0;
  u32x8 bayer = {};
  if constexpr (kFormat != 0) GB_LOAD8(bayer, s.bayer);
  u32x8 passed = {};
  for (unsigned i = 0; i < s.count; i += 8) {
    const unsigned n = s.count - i < 8 ? s.count - i : 8;
    // A tail chunk loads a full vector when the row has room. Not for textured spans: their short
    // spans (2-7 pixels) then reach into another cache line more often, and the perspective road
    // lost 7% (cubes unchanged), while untextured 1,000-px spans gained 10%.
    const bool whole = !kTextured && i + 8 <= s.room;
    u32x8 pass = GB_MASK((i32x8)lane < static_cast<std::int32_t>(n));
    std::uint8_t* cp = s.color + std::size_t{i} * kBpp;
    bool none = false, all = n == 8;
    if (depth) {
      std::uint8_t* zp = s.depth + std::size_t{i} * 4;
      const u32x8 z = q[4] & s.zmask;
      u32x8 old;
      GB_LOAD_N(old, zp, n, whole);  // lanes beyond n are masked off
      if (s.z_test) {
        const i32x8 zi = (i32x8)z, di = (i32x8)(GB_BSWAP(old) & 0xFFFFFFu);  // both < 2^24
        GB_DEPTH_TEST(pass, zi, di, s.z_func);
      }
      std::uint64_t m[4];
      std::memcpy(m, &pass, sizeof m);
      none = (m[0] | m[1] | m[2] | m[3]) == 0;
      all = all && (m[0] & m[1] & m[2] & m[3]) == ~std::uint64_t{0};
      if (s.z_write && !none) {
        const u32x8 zs = GB_BSWAP(z);
        const u32x8 out = (zs & pass) | (old & ~pass);
        GB_COPY(zp, &out, n);
      }
    }
    // Rejected chunks touch no colour; fully passing chunks store without reading.
    if (!none) {
      u32x8 word = u32x8{} + s.flat;
      if (s.gouraud) word = (q[0] & 255u) | ((q[1] & 255u) << 8) | ((q[2] & 255u) << 16) | (q[3] << 24);
      if constexpr (kTextured) word = texture8(s.texture, q[5], q[6], q[7], pass, n, word);
      if constexpr (kFormat != 0) {
        simd::write_packed8<kFormat>(cp, n, word, pass, reads_color || !all, s.blend, bayer, s.temporal, s.keep_packed,
                                    whole);
      } else if (reads_color || !all) {
        u32x8 cold;
        GB_LOAD_N(cold, cp, n, whole);
        if (s.blend != 0) word = GB_BLEND8(s.blend, word, cold);
        word = (word & ~s.keep) | (cold & s.keep);
        const u32x8 out = (word & pass) | (cold & ~pass);
        GB_COPY(cp, &out, n);
      } else {
        std::memcpy(cp, &word, 32);  // fully passing chunk of a plain store: no read
      }
      passed -= pass;  // pass lanes are all ones (−1)
    }
    for (unsigned p = first; p < kUsed; ++p) {
      q[p] += s.q8[p];
      r[p] += s.r8[p];
      const u32x8 carry = GB_MASK((i32x8)r[p] >= (i32x8)den);
      r[p] -= den & carry;
      q[p] -= carry;  // carry lanes are all ones (−1)
    }
  }
  std::uint64_t total = 0;
  for (unsigned k = 0; k < 8; ++k) total += passed[k];
  return total;
}

__attribute__((target_clones("avx2", "default"))) std::uint64_t shade_span_simd(const SimdSpan& s) {
  switch (s.format) {
    case 1: return s.texture.tex ? shade_span<true, 1>(s) : shade_span<false, 1>(s);
    case 2: return s.texture.tex ? shade_span<true, 2>(s) : shade_span<false, 2>(s);
    default: return s.texture.tex ? shade_span<true, 0>(s) : shade_span<false, 0>(s);
  }
}

}  // namespace gpubridge::sim
