#include "narrow_simd.hpp"

#include "pixel8.hpp"

namespace gpubridge::sim {

using protocol::PixelFormat;
using simd::i32x8;
using simd::u32x8;

// One instance per plane count (constant loop bounds keep the lanes in registers).
template <bool kTextured, PixelFormat kFormat>
[[gnu::always_inline]] inline NarrowCounts shade_narrow(const NarrowTriangle& t) {
  const PixelLanes& px = t.pixel;
  const i32x8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
  const u32x8 in_box = simd::mask(lane < static_cast<std::int32_t>(t.width));
  i32x8 e[3];
  for (unsigned i = 0; i < 3; ++i) e[i] = t.e[i] + lane * t.ex[i];
  // Plane lanes: (q0 + k·qx, r0 + k·rx) with r < 8·den, brought below den by subtracting 4, 2
  // and 1 den where it fits (exact floor-divmod). q wraps modulo 2^32; covered lanes hold
  // attribute values, which are far below 2^32, so they are exact.
  const unsigned first = px.gouraud ? 0 : 4;
  const simd::StageFlags flags = simd::stage_flags(px);
  const unsigned last = kTextured ? 8 : flags.depth ? 5 : 4;
  const u32x8 den = u32x8{} + t.den;
  // Only planes first..last-1 are read; no zero fill (a `rep stos` here cost more than a row).
  u32x8 q[NarrowTriangle::kPlanes], r[NarrowTriangle::kPlanes];
  for (unsigned p = first; p < last; ++p) {
    q[p] = t.q[p] + (u32x8)lane * t.qx[p];
    r[p] = t.r[p] + (u32x8)lane * t.rx[p];
    for (unsigned s = 4; s >= 1; s >>= 1) {
      const u32x8 c = simd::mask((i32x8)r[p] >= (i32x8)(den * s));
      r[p] -= (den * s) & c;
      q[p] += s & c;
    }
  }
  u32x8 covered = {}, passed = {};
  std::uint8_t* cp = t.color;
  std::uint8_t* zp = t.depth;
  for (unsigned row = 0; row < t.rows; ++row) {
    const u32x8 cov = in_box & simd::mask((e[0] | e[1] | e[2]) >= 0);
    u32x8 bayer = {};
    if constexpr (kFormat != PixelFormat::RGBA8888) bayer = simd::load8(t.bayer[row & 3]);
    // The box's eight lanes lie inside the framebuffer row (the caller checks): whole rows.
    passed -= simd::pixel8<kTextured, kFormat, simd::Chunk::Row>(px, flags, q, cov, cp, zp, 8, true, bayer);
    covered -= cov;  // mask lanes are all ones (−1)
    cp += t.color_pitch;
    if (flags.depth) zp += t.pitch;
    for (unsigned i = 0; i < 3; ++i) e[i] += t.ey[i];
    for (unsigned p = first; p < last; ++p) {
      q[p] += t.qy[p];
      r[p] += t.ry[p];
      simd::carry(q[p], r[p], den);
    }
  }
  NarrowCounts n;
  for (unsigned k = 0; k < 8; ++k) {
    n.covered += covered[k];
    n.passed += passed[k];
  }
  return n;
}

__attribute__((target_clones("avx2", "default"))) NarrowCounts shade_narrow_simd(const NarrowTriangle& t) {
  return simd::dispatch(t.pixel, [&]<bool kTextured, PixelFormat kFormat>() __attribute__((always_inline)) {
    return shade_narrow<kTextured, kFormat>(t);
  });
}

}  // namespace gpubridge::sim
