#include "span_simd.hpp"

#include <cstdlib>
#include <cstring>

#include "cpu_features.hpp"
#include "gpubridge/common/log.hpp"
#include "pixel8.hpp"
#include "setup.hpp"

namespace gpubridge::sim {

using protocol::PixelFormat;
using simd::i32x8;
using simd::u32x8;

// One instance per plane count and colour source, so the plane loops have constant bounds and the
// lanes stay in registers (a run-time bound cost the untextured spans 5-15%; a run-time first
// plane, Gouraud or not, kept every plane's lanes on the stack, loaded and stored on every chunk).
// kAvx2: the instance has AVX2 or AVX-512 (pixel8's byte shuffle and lane bits); kAvx512: it has
// AVX-512 (texture8's lanes for perspective repeat textures, texture8_wide.hpp).
template <bool kTextured, PixelFormat kFormat, bool kGouraud, bool kAvx2, bool kAvx512 = false>
[[gnu::always_inline]] inline std::uint64_t shade_span(const SimdSpan& s) {
  constexpr std::size_t kBpp = protocol::bytes_per_pixel(kFormat);
  constexpr unsigned kUsed = kTextured ? 8 : 5;
  constexpr unsigned first = kGouraud ? 0 : 4;
  // Local copies of what the loop reads of the span: the colour and depth stores go through
  // std::uint8_t pointers, which may alias `s`, so its fields would be read again on every chunk.
  // (The copy's gouraud is this instance's constant, so the colour's source is no branch either.)
  PixelLanes px = s.pixel;
  px.gouraud = kGouraud;
  const unsigned count = s.count, room = s.room;
  if constexpr (kTextured) {
    // Q constant along x (a screen row at one depth, the road's case: its triangles have a
    // horizontal edge of equal W): every pixel of the span has the span's first Q, so the
    // reciprocal is computed once a span rather than once a pixel. Same integers: lane k's Q is
    // q0 + k·0 and r0 < den, and texture8's constant-Q loop is its per-lane loop with that one
    // reciprocal. Q = 0 keeps the per-lane loop (its texel coordinates are (0, 0)). Planes in
    // setup.hpp's attribute order.
    if (!px.texture.q_const && s.qx[kQ] == 0 && s.rk[kQ][1] == 0 && s.q0[kQ] != 0) {
      px.texture.q_const = true;
      px.texture.const_rc = (*px.texture.recip)(s.q0[kQ]);
    }
  }
  u32x8 q[kUsed] = {}, r[kUsed] = {}, q8[kUsed] = {}, r8[kUsed] = {};  // unused planes: zeros, never read
  const u32x8 den = u32x8{} + s.den;
  // The rasteriser hands over the planes at the span's first pixel (its cursor): lane k adds k
  // steps. (The routine used to jump from the box row's start itself, a double-vector division
  // per span; the cursor made that jump unnecessary.)
  for (unsigned p = first; p < kUsed; ++p) {
    q[p] = simd::load8(s.qk[p]) + s.q0[p];
    r[p] = simd::load8(s.rk[p]) + s.r0[p];
    simd::carry(q[p], r[p], den);
    q8[p] = u32x8{} + s.q8[p];
    r8[p] = u32x8{} + s.r8[p];
  }
  const simd::StageFlags flags = simd::stage_flags(px);
  u32x8 bayer = {};
  if constexpr (kFormat != PixelFormat::RGBA8888) bayer = simd::load8(s.bayer);
  u32x8 passed = {};
  std::uint8_t* cp = s.color;
  std::uint8_t* zp = s.depth;
  // Whole chunks of eight: every lane a pixel (n = 8 is a constant, so no lane mask and no tail
  // branch in the loads and stores); the planes step only when another chunk follows.
  unsigned i = 0;
  for (; i + 8 <= count; i += 8) {
    if (i != 0) {
      for (unsigned p = first; p < kUsed; ++p) {
        q[p] += q8[p];
        r[p] += r8[p];
        simd::carry(q[p], r[p], den);
      }
    }
    passed -= simd::pixel8<kTextured, kFormat, simd::Chunk::Span, false, false, kAvx2, kAvx512>(
        px, flags, q, ~u32x8{}, cp, zp, 8, true, bayer);
    cp += 8 * kBpp;
    if (flags.depth) zp += 8 * 4;  // s.depth is null without depth
  }
  if (i < count) {  // the last 1-7 pixels
    if (i != 0) {
      for (unsigned p = first; p < kUsed; ++p) {
        q[p] += q8[p];
        r[p] += r8[p];
        simd::carry(q[p], r[p], den);
      }
    }
    const unsigned n = count - i;
    const i32x8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
    const u32x8 in_span = simd::mask(lane < static_cast<std::int32_t>(n));
    // The tail loads a full vector when the row has room. Not for textured spans: their short
    // spans (2-7 pixels) then reach into another cache line more often, and the perspective road
    // lost 7% (cubes unchanged), while untextured 1,000-px spans gained 10%.
    const bool whole = !kTextured && i + 8 <= room;
    passed -= simd::pixel8<kTextured, kFormat, simd::Chunk::Span, false, false, kAvx2, kAvx512>(
        px, flags, q, in_span, cp, zp, n, whole, bayer);
  }
  return simd::lane_sum(passed);  // pass lanes are all ones (−1)
}

// The AVX-512 instance's long untextured RGBA8888 spans in sixteen lanes (512-bit vectors): chunks
// of sixteen while more than eight pixels remain, the last 1-8 in one chunk of eight lanes (the low
// half of the sixteen) rather than a mostly empty sixteen. Lanes 8..15 start one 8-pixel step
// (q8, r8) after lanes 0..7 and all advance by twice that step, with one carry each: the same
// integers as eight lanes. kMasked: partial chunks through AVX-512's masked moves.
[[gnu::always_inline]] inline simd::u32x16 join(u32x8 lo, u32x8 hi) {
  return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
}
[[gnu::always_inline]] inline u32x8 low_half(simd::u32x16 v) { return __builtin_shufflevector(v, v, 0, 1, 2, 3, 4, 5, 6, 7); }

template <bool kMasked, bool kGouraud>
[[gnu::always_inline]] inline std::uint64_t shade_span_wide(const SimdSpan& s) {
  using simd::u32x16;
  constexpr PixelFormat kFormat = PixelFormat::RGBA8888;
  constexpr unsigned kUsed = 5;  // untextured: R, G, B, A, Z
  constexpr unsigned first = kGouraud ? 0 : 4;
  PixelLanes px = s.pixel;  // local copies, as in shade_span
  px.gouraud = kGouraud;
  const unsigned count = s.count, room = s.room;
  const u32x8 den8 = u32x8{} + s.den;
  const u32x16 den = u32x16{} + s.den;
  u32x16 q[kUsed] = {}, r[kUsed] = {};
  std::uint32_t q16[kUsed] = {}, r16[kUsed] = {};
  for (unsigned p = first; p < kUsed; ++p) {
    u32x8 ql = simd::load8(s.qk[p]) + s.q0[p], rl = simd::load8(s.rk[p]) + s.r0[p];
    simd::carry(ql, rl, den8);
    u32x8 qh = ql + s.q8[p], rh = rl + s.r8[p];
    simd::carry(qh, rh, den8);
    q[p] = join(ql, qh);
    r[p] = join(rl, rh);
    const bool over = 2 * s.r8[p] >= s.den;  // r8 < den < 2^30: no overflow
    q16[p] = 2 * s.q8[p] + over;
    r16[p] = 2 * s.r8[p] - (over ? s.den : 0);
  }
  const simd::i32x16 lane = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
  const simd::StageFlags flags = simd::stage_flags(px);
  u32x16 passed = {};
  std::uint8_t* cp = s.color;
  std::uint8_t* zp = s.depth;
  unsigned i = 0;
  for (; i + 8 < count; i += 16) {
    const unsigned n = count - i < 16 ? count - i : 16;
    const u32x16 in_span = simd::mask(lane < static_cast<std::int32_t>(n));
    passed -= simd::pixel8<false, kFormat, simd::Chunk::Span, false, kMasked, true>(px, flags, q, in_span, cp, zp, n,
                                                                                    i + 16 <= room, u32x16{});
    cp += 16 * 4;
    if (flags.depth) zp += 16 * 4;  // s.depth is null without depth
    for (unsigned p = first; p < kUsed; ++p) {
      q[p] += q16[p];
      r[p] += r16[p];
      simd::carry(q[p], r[p], den);
    }
  }
  std::uint64_t total = 0;
  if (i < count) {
    const unsigned n = count - i;  // 1..8
    u32x8 qt[kUsed];
    for (unsigned p = first; p < kUsed; ++p) qt[p] = low_half(q[p]);
    const i32x8 lane8 = {0, 1, 2, 3, 4, 5, 6, 7};
    const u32x8 in_span = simd::mask(lane8 < static_cast<std::int32_t>(n));
    const u32x8 tail = simd::pixel8<false, kFormat, simd::Chunk::Span, false, kMasked, true>(
        px, flags, qt, in_span, cp, zp, n, i + 8 <= room, u32x8{});
    total = simd::lane_sum(u32x8{} - tail);  // pass lanes are all ones (−1)
  }
  return total + simd::lane_sum(passed);
}

namespace {

// Each instance is the same source compiled for one ISA; all of them compute the same integers.
// The *_of functions are one draw's specialisation (texture, colour format, colour source): what
// span_routine hands the rasteriser once per triangle, so that a span pays neither the instance
// look-up nor the dispatch (about 35 instructions a span of the 1,000-px front's ~30 pixels).
template <bool kTextured, PixelFormat kFormat, bool kGouraud>
[[gnu::noinline]] std::uint64_t span_baseline_of(const SimdSpan& s) {
  return shade_span<kTextured, kFormat, kGouraud, false>(s);
}
template <bool kTextured, PixelFormat kFormat, bool kGouraud>
[[gnu::noinline]] __attribute__((target("avx2"))) std::uint64_t span_avx2_of(const SimdSpan& s) {
  return shade_span<kTextured, kFormat, kGouraud, true>(s);
}
// AVX-512 (F, VL, BW, DQ) in 256-bit vectors: the same eight lanes with 32 vector registers and
// compares into mask registers. Tails as in AVX2 (whole loads where the row has room, stores of n
// words): masked moves for them cost the road 15 % and the 1,000-px front rows a few per cent.
#define SPAN_AVX512 __attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq")))
template <bool kTextured, PixelFormat kFormat, bool kGouraud>
[[gnu::noinline]] SPAN_AVX512 std::uint64_t span_avx512_256_of(const SimdSpan& s) {
  return shade_span<kTextured, kFormat, kGouraud, true, true>(s);
}
// Untextured RGBA8888 spans of at least kWideSpan pixels in sixteen lanes (shade_span_wide, tails
// through masked moves: the 50,000-px front rows 108-113 → 101-102 ms a frame against unmasked
// tails); every other span as span_avx512_256_of. Shorter spans stay in eight lanes: sixteen for
// spans from 9 or 32 pixels on cost the 1,000-px front rows a few per cent (spans of 20-45 pixels,
// where the second set of lanes' start and the 8-lane tail are paid on every row); from 64 they
// do not (docs/simulator.md, issue 17's AVX-512 part).
constexpr unsigned kWideSpan = 64;
template <bool kTextured, PixelFormat kFormat, bool kGouraud>
[[gnu::noinline]] SPAN_AVX512 std::uint64_t span_avx512_of(const SimdSpan& s) {
  if constexpr (!kTextured && kFormat == PixelFormat::RGBA8888) {
    if (s.count >= kWideSpan) return shade_span_wide<true, kGouraud>(s);
  }
  return shade_span<kTextured, kFormat, kGouraud, true, true>(s);
}

#undef SPAN_AVX512

// The widest instance the CPU runs, capped by GPUBRIDGE_SIM_SPAN_ISA (avx512-256, avx2 or baseline)
// so that the instances can be timed against each other in one binary. Any other value is named
// in a warning and caps nothing: a typo must not pass for a measurement of another instance.
SpanIsa pick_instance() {
  SpanIsa cap = SpanIsa::Avx512;
  if (const char* env = std::getenv("GPUBRIDGE_SIM_SPAN_ISA"); env && *env) {
    if (std::strcmp(env, "avx512-256") == 0) cap = SpanIsa::Avx512x256;
    else if (std::strcmp(env, "avx2") == 0) cap = SpanIsa::Avx2;
    else if (std::strcmp(env, "baseline") == 0) cap = SpanIsa::Baseline;
    else
      logger("sim")->warn("GPUBRIDGE_SIM_SPAN_ISA={} is not one of avx512-256, avx2, baseline: ignored, the span "
                          "routine runs the widest instance this CPU has",
                          env);
  }
  if (cap == SpanIsa::Avx512 && cpu_has_avx512()) return SpanIsa::Avx512;
  if (cap == SpanIsa::Avx512x256 && cpu_has_avx512()) return SpanIsa::Avx512x256;
  if (cap != SpanIsa::Baseline && cpu_has_avx2()) return SpanIsa::Avx2;
  return SpanIsa::Baseline;
}

SpanIsa instance() {
  static const SpanIsa picked = pick_instance();
  return picked;
}

}  // namespace

SpanIsa span_simd_isa() { return instance(); }

SpanRoutine span_routine(const PixelLanes& px) {
  const SpanIsa isa = instance();
  return simd::dispatch(px, [&]<bool kTextured, PixelFormat kFormat>() -> SpanRoutine {
    const bool g = px.gouraud;
    switch (isa) {
      case SpanIsa::Avx512:
        return g ? &span_avx512_of<kTextured, kFormat, true> : &span_avx512_of<kTextured, kFormat, false>;
      case SpanIsa::Avx512x256:
        return g ? &span_avx512_256_of<kTextured, kFormat, true> : &span_avx512_256_of<kTextured, kFormat, false>;
      case SpanIsa::Avx2:
        return g ? &span_avx2_of<kTextured, kFormat, true> : &span_avx2_of<kTextured, kFormat, false>;
      case SpanIsa::Baseline: break;
    }
    return g ? &span_baseline_of<kTextured, kFormat, true> : &span_baseline_of<kTextured, kFormat, false>;
  });
}

std::uint64_t shade_span_simd(const SimdSpan& s) { return span_routine(s.pixel)(s); }

}  // namespace gpubridge::sim
