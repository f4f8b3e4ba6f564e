#include "span_simd.hpp"

#include "pixel8.hpp"

namespace gpubridge::sim {

using protocol::PixelFormat;
using simd::i32x8;
using simd::u32x8;

// (q0, r0) of every plane advanced s.skip pixels: the floor-divmod of r0 + rx·skip by den for all
// eight planes at once in double lanes, without branches. With den < 2^30 and skip < 2^11 the
// numerator is below 2^41, exact in double; the truncated estimate of its (non-negative) quotient
// is off by at most one, and one select each way corrects it. Done here rather than in the
// rasteriser's row loop, where five scalar divisions and their correction loops were a quarter of
// its per-row time (1,000-px triangles; perf).
[[gnu::always_inline]] inline void span_start(const SimdSpan& s, std::uint32_t* q0, std::uint32_t* r0) {
  // Four lanes at a time, corrections as masks (GCC splits 8-lane double selects into scalars).
  using f64x4 = double __attribute__((vector_size(32)));
  using i64x4 = std::int64_t __attribute__((vector_size(32)));
  using i32x4 = std::int32_t __attribute__((vector_size(16)));
  const f64x4 den = f64x4{} + static_cast<double>(s.den), one = f64x4{} + 1.0;
  const double skip = static_cast<double>(s.skip);
  i32x4 qd[2], rd[2];
  for (unsigned h = 0; h < 2; ++h) {
    i32x4 ri;
    f64x4 rx;
    std::memcpy(&ri, s.r0 + 4 * h, sizeof ri);
    std::memcpy(&rx, s.rx + 4 * h, sizeof rx);
    const f64x4 num = __builtin_convertvector(ri, f64x4) + rx * skip;
    f64x4 q = __builtin_convertvector(__builtin_convertvector(num * s.inv_den, i32x4), f64x4);
    f64x4 r = num - q * den;
    i64x4 low = r < 0;  // estimate one too high
    q -= (f64x4)((i64x4)one & low);
    r += (f64x4)((i64x4)den & low);
    const i64x4 high = r >= den;  // one too low
    q += (f64x4)((i64x4)one & high);
    r -= (f64x4)((i64x4)den & high);
    qd[h] = __builtin_convertvector(q, i32x4);
    rd[h] = __builtin_convertvector(r, i32x4);
  }
  u32x8 qv, rv;
  std::memcpy(&qv, qd, sizeof qv);
  std::memcpy(&rv, rd, sizeof rv);
  const u32x8 qs = simd::load8(s.q0) + simd::load8(s.qx) * s.skip + qv;  // modulo 2^32
  std::memcpy(q0, &qs, sizeof qs);
  std::memcpy(r0, &rv, sizeof rv);
}

// One instance per plane count, so the plane loops have constant bounds and the lanes stay in
// registers (a run-time bound cost the untextured spans 5-15%).
template <bool kTextured, PixelFormat kFormat>
[[gnu::always_inline]] inline std::uint64_t shade_span(const SimdSpan& s) {
  constexpr std::size_t kBpp = protocol::bytes_per_pixel(kFormat);
  constexpr unsigned kUsed = kTextured ? 8 : 5;
  u32x8 q[kUsed], r[kUsed];
  const PixelLanes& px = s.pixel;
  const unsigned first = px.gouraud ? 0 : 4;
  const u32x8 den = u32x8{} + s.den;
  std::uint32_t q0[8], r0[8];
  span_start(s, q0, r0);
  for (unsigned p = first; p < kUsed; ++p) {
    q[p] = simd::load8(s.qk[p]) + q0[p];
    r[p] = simd::load8(s.rk[p]) + r0[p];
    simd::carry(q[p], r[p], den);
  }
  const i32x8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
  const simd::StageFlags flags = simd::stage_flags(px);
  u32x8 bayer = {};
  if constexpr (kFormat != PixelFormat::RGBA8888) bayer = simd::load8(s.bayer);
  u32x8 passed = {};
  std::uint8_t* cp = s.color;
  std::uint8_t* zp = s.depth;
  for (unsigned i = 0; i < s.count; i += 8) {
    const unsigned n = s.count - i < 8 ? s.count - i : 8;
    // A tail chunk loads a full vector when the row has room. Not for textured spans: their short
    // spans (2-7 pixels) then reach into another cache line more often, and the perspective road
    // lost 7% (cubes unchanged), while untextured 1,000-px spans gained 10%.
    const bool whole = !kTextured && i + 8 <= s.room;
    const u32x8 in_span = simd::mask(lane < static_cast<std::int32_t>(n));
    passed -= simd::pixel8<kTextured, kFormat, simd::Chunk::Span>(px, flags, q, in_span, cp, zp, n, whole, bayer);
    cp += 8 * kBpp;
    if (flags.depth) zp += 8 * 4;  // s.depth is null without depth
    for (unsigned p = first; p < kUsed; ++p) {
      q[p] += s.q8[p];
      r[p] += s.r8[p];
      simd::carry(q[p], r[p], den);
    }
  }
  std::uint64_t total = 0;
  for (unsigned k = 0; k < 8; ++k) total += passed[k];  // pass lanes are all ones (−1)
  return total;
}

__attribute__((target_clones("avx2", "default"))) std::uint64_t shade_span_simd(const SimdSpan& s) {
  return simd::dispatch(s.pixel, [&]<bool kTextured, PixelFormat kFormat>() __attribute__((always_inline)) {
    return shade_span<kTextured, kFormat>(s);
  });
}

}  // namespace gpubridge::sim
