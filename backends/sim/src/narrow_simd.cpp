#include "narrow_simd.hpp"

#include "packed_lanes.hpp"
#include "simd_lanes.hpp"
#include "texture8.hpp"

namespace gpubridge::sim {
namespace {

using simd::i32x8;
using simd::u32x8;
// r < den after one carry: r may reach 2·den − 2 < 2^31, so the signed compare is exact.
#define GB_CARRY(q, r, den)                               \
  do {                                                    \
    const u32x8 c_ = GB_MASK((i32x8)(r) >= (i32x8)(den)); \
    (r) -= (den) & c_;                                    \
    (q) -= c_;                                            \
  } while (0)

// One instance per plane count (constant loop bounds keep the lanes in registers).
template <bool kTextured, unsigned kFormat>
[[gnu::always_inline]] inline NarrowCounts shade_narrow(const NarrowTriangle& t) {
  const i32x8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
  const u32x8 in_box = GB_MASK(lane < static_cast<std::int32_t>(t.width));
  i32x8 e[3];
  for (unsigned i = 0; i < 3; ++i) e[i] = t.e[i] + lane * t.ex[i];
  // Plane lanes: (q0 + k·qx, r0 + k·rx) with r < 8·den, brought below den by subtracting 4, 2
  // and 1 den where it fits (exact floor-divmod). q wraps modulo 2^32; covered lanes hold
  // attribute values, which are far below 2^32, so they are exact.
  const unsigned first = t.gouraud ? 0 : 4;
  const bool depth = t.z_test || t.z_write;
  const unsigned last = kTextured ? 8 : depth ? 5 : 4;
  const u32x8 den = u32x8{} + t.den;
  // Only planes first..last-1 are read; no zero fill (a `rep stos` here cost more than a row).
  u32x8 q[NarrowTriangle::kPlanes], r[NarrowTriangle::kPlanes];
  for (unsigned p = first; p < last; ++p) {
    q[p] = t.q[p] + (u32x8)lane * t.qx[p];
    r[p] = t.r[p] + (u32x8)lane * t.rx[p];
    for (unsigned s = 4; s >= 1; s >>= 1) {
      const u32x8 c = GB_MASK((i32x8)r[p] >= (i32x8)(den * s));
      r[p] -= (den * s) & c;
      q[p] += s & c;
    }
  }
  u32x8 covered = {}, passed = {};
  std::uint8_t* cp = t.color;
  std::uint8_t* zp = t.depth;
  for (unsigned row = 0; row < t.rows; ++row) {
    const u32x8 cov = in_box & GB_MASK((e[0] | e[1] | e[2]) >= 0);
    u32x8 pass = cov;
    if (depth) {
      u32x8 old;
      GB_LOAD8(old, zp);
      const u32x8 z = q[4] & t.zmask;
      if (t.z_test) {
        const i32x8 zi = (i32x8)z, di = (i32x8)(GB_BSWAP(old) & 0xFFFFFFu);  // both < 2^24
        GB_DEPTH_TEST(pass, zi, di, t.z_func);
      }
      if (t.z_write) {
        const u32x8 out = (GB_BSWAP(z) & pass) | (old & ~pass);
        GB_STORE8(zp, out);
      }
      zp += t.pitch;
    }
    u32x8 word = u32x8{} + t.flat;
    if (t.gouraud) word = (q[0] & 255u) | ((q[1] & 255u) << 8) | ((q[2] & 255u) << 16) | (q[3] << 24);
    if constexpr (kTextured) word = texture8(t.texture, q[5], q[6], q[7], pass, 8, word);
    if constexpr (kFormat != 0) {
      u32x8 bayer;
      GB_LOAD8(bayer, t.bayer[row & 3]);
      simd::write_packed8<kFormat>(cp, 8, word, pass, true, t.blend, bayer, t.temporal, t.keep_packed, true);
    } else {
      u32x8 cold;
      GB_LOAD8(cold, cp);
      if (t.blend != 0) word = GB_BLEND8(t.blend, word, cold);
      word = (word & ~t.keep) | (cold & t.keep);
      const u32x8 out = (word & pass) | (cold & ~pass);
      GB_STORE8(cp, out);
    }
    cp += t.color_pitch;
    covered -= cov;  // mask lanes are all ones (−1)
    passed -= pass;
    for (unsigned i = 0; i < 3; ++i) e[i] += t.ey[i];
    for (unsigned p = first; p < last; ++p) {
      q[p] += t.qy[p];
      r[p] += t.ry[p];
      GB_CARRY(q[p], r[p], den);
    }
  }
  NarrowCounts n;
  for (unsigned k = 0; k < 8; ++k) {
    n.covered += covered[k];
    n.passed += passed[k];
  }
  return n;
}


}  // namespace

__attribute__((target_clones("avx2", "default"))) NarrowCounts shade_narrow_simd(const NarrowTriangle& t) {
  switch (t.format) {
    case 1: return t.texture.tex ? shade_narrow<true, 1>(t) : shade_narrow<false, 1>(t);
    case 2: return t.texture.tex ? shade_narrow<true, 2>(t) : shade_narrow<false, 2>(t);
    default: return t.texture.tex ? shade_narrow<true, 0>(t) : shade_narrow<false, 0>(t);
  }
}

}  // namespace gpubridge::sim
