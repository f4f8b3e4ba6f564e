#include "preview_simd.hpp"

#include "pixel8.hpp"

namespace gpubridge::sim {

using protocol::PixelFormat;
using simd::i32x8;
using simd::u32x8;
typedef float f32x8 __attribute__((vector_size(32)));

namespace {

// v clamped into [lo, hi] (NaN goes to lo): the only way a float lane becomes an integer here, so
// no conversion meets a value it cannot represent. Written as maxps / minps compute (the second
// operand when the compare is false or unordered), so each bound is one instruction.
[[gnu::always_inline]] inline f32x8 clamp(f32x8 v, float lo, float hi) {
  const f32x8 l = f32x8{} + lo, h = f32x8{} + hi;
  v = v > l ? v : l;
  return v < h ? v : h;
}
// Truncation of lanes already inside [0, 2^31) or (-2^31, 2^31).
[[gnu::always_inline]] inline u32x8 to_u32(f32x8 v) { return (u32x8)__builtin_convertvector(v, i32x8); }
// floor of lanes clamped into [-2^30, 2^30].
[[gnu::always_inline]] inline u32x8 floor_u32(f32x8 v) {
  const i32x8 t = __builtin_convertvector(v, i32x8);
  return (u32x8)(t + (__builtin_convertvector(t, f32x8) > v));  // a true compare lane is −1
}

template <bool kTextured, PixelFormat kFormat, bool kNarrow>
[[gnu::always_inline]] inline PreviewCounts shade_preview(const PreviewRows& t) {
  constexpr std::size_t kBpp = protocol::bytes_per_pixel(kFormat);
  constexpr simd::Chunk kChunk = kNarrow ? simd::Chunk::Row : simd::Chunk::Span;
  const PixelLanes& px = t.pixel;
  const simd::StageFlags flags = simd::stage_flags(px);
  const i32x8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
  const f32x8 lanef = __builtin_convertvector(lane, f32x8);
  PreviewCounts counts;
  u32x8 covered = {}, passed = {};
  std::uint8_t* crow = t.color;
  std::uint8_t* zrow = t.depth;
  // Wide boxes walk their rows' spans; narrow ones test the edges in lanes.
  SpanWalk walk;
  if constexpr (!kNarrow) walk.start(t.e, t.ex, t.ey, t.ky0);
  for (int r = 0; r < t.rows; ++r, crow += t.color_pitch, zrow += flags.depth ? t.pitch : 0) {
    const int ky = t.ky0 + r;
    std::int64_t e[3];
    for (int i = 0; i < 3; ++i) e[i] = t.e[i] + ky * t.ey[i];
    int kl = 0, kr = t.width - 1;
    if constexpr (!kNarrow) {
      const bool any = walk.span(t.width, kl, kr);
      walk.next_row();
      if (!any) continue;
    }
    const unsigned count = static_cast<unsigned>(kr - kl + 1);
    counts.scanned += count;
    if constexpr (!kNarrow) {
      // Rows two ahead (about this span) are fetched while this one is drawn, as the exact span
      // routine does: random triangles miss the caches, and a depth read that waits on memory was
      // a quarter of the time of 1,000-px triangles without it.
      if (r + 2 < t.rows) {
        const std::uint8_t* c2 = crow + 2 * t.color_pitch + static_cast<std::size_t>(kl) * kBpp;
        for (std::size_t b = 0; b < count * kBpp; b += 64) __builtin_prefetch(c2 + b, 1);
        if (flags.depth) {
          const std::uint8_t* z2 = zrow + 2 * t.pitch + static_cast<std::size_t>(kl) * 4;
          for (std::size_t b = 0; b < count * 4u; b += 64) __builtin_prefetch(z2 + b, 1);
        }
      }
    }
    // The planes at the span's first pixel, from the box origin in double (not stepped from the
    // band's first row, so no thread sees other values), then float lanes along the span: each
    // lane's error is that of its offset from the anchor, not of the box's extent.
    const double kyd = ky, kld = kl;
    f32x8 rb[PreviewRows::kPlanes] = {}, dxf[PreviewRows::kPlanes] = {};  // broadcast once per row
    for (unsigned p = 0; p < PreviewRows::kPlanes; ++p) {
      if (!(px.gouraud && p < 4) && !(flags.depth && p == 4) && !(kTextured && p >= 5)) continue;
      rb[p] = f32x8{} + static_cast<float>(t.base[p] + t.dy[p] * kyd + t.dx[p] * kld);
      dxf[p] = f32x8{} + static_cast<float>(t.dx[p]);
    }
    f32x8 kx = lanef;  // lane offsets from the anchor
    u32x8 in_tri = ~u32x8{};
    if constexpr (kNarrow) {
      // Float edge lanes: float(exact E at lane 0) + k·ex keeps the integer value's sign.
      auto edge = [&](int i) __attribute__((always_inline)) { return (f32x8{} + static_cast<float>(e[i])) + lanef * static_cast<float>(t.ex[i]) >= 0.0f; };
      const i32x8 ok = edge(0) & edge(1) & edge(2);
      in_tri = (u32x8)ok;
    }
    std::uint8_t* cp = crow + static_cast<std::size_t>(kl) * kBpp;
    std::uint8_t* zp = flags.depth ? zrow + static_cast<std::size_t>(kl) * 4 : nullptr;
    for (unsigned i = 0; i < count; i += 8) {
      const unsigned n = count - i < 8 ? count - i : 8;
      const unsigned col = static_cast<unsigned>(kl) + i;
      const bool whole = kNarrow ? col + 8 <= t.room : (!kTextured && col + 8 <= t.room);
      u32x8 pass = simd::mask(lane < static_cast<std::int32_t>(n));
      if constexpr (kNarrow) pass &= in_tri;
      // Constant plane indices and bounds (not a loop from `first` to `last`): the lanes stay in
      // registers and each clamp bound is one instruction.
      u32x8 q[PreviewRows::kPlanes] = {};
      if (px.gouraud)
        for (unsigned p = 0; p < 4; ++p) q[p] = to_u32(clamp(rb[p] + dxf[p] * kx, 0.0f, 255.0f));
      if (flags.depth) q[4] = to_u32(clamp(rb[4] + dxf[4] * kx, 0.0f, 16777215.0f));
      if constexpr (kTextured) {
        // Perspective: S/Q and T/Q from one divide per 8 lanes (correctly rounded, so the same bits
        // on every CPU, unlike an rcpps estimate), in 1/4096 texel; Q <= 0 (only by rounding: Q is
        // unsigned) samples texel (0, 0) as the exact path does for Q = 0.
        const f32x8 sv = rb[5] + dxf[5] * kx, tv = rb[6] + dxf[6] * kx, qv = rb[7] + dxf[7] * kx;
        const u32x8 q_ok = (u32x8)(qv > 0.0f);
        const f32x8 inv = 1.0f / (q_ok ? qv : f32x8{} + 1.0f);
        q[5] = floor_u32(clamp(sv * (inv * t.scale_u), -0x1p30f, 0x1p30f)) & q_ok;
        q[6] = floor_u32(clamp(tv * (inv * t.scale_v), -0x1p30f, 0x1p30f)) & q_ok;
      }
      u32x8 bayer = {};
      if constexpr (kFormat != PixelFormat::RGBA8888)
        if (t.dither) bayer = simd::load8(t.bayer[ky & 3][col & 3]);
      if constexpr (kNarrow) covered -= pass;
      passed -= simd::pixel8<kTextured, kFormat, kChunk, true>(px, flags, q, pass, cp, zp, n, whole, bayer);
      kx += 8.0f;
      cp += 8 * kBpp;
      if (flags.depth) zp += 8 * 4;
    }
    if constexpr (!kNarrow) counts.covered += count;
  }
  for (unsigned k = 0; k < 8; ++k) {  // mask lanes are all ones (−1)
    counts.covered += covered[k];
    counts.passed += passed[k];
  }
  return counts;
}

}  // namespace

__attribute__((target_clones("avx2", "default"))) PreviewCounts shade_preview_simd(const PreviewRows& t) {
  const bool narrow = t.width <= 8;
  return simd::dispatch(t.pixel, [&]<bool kTextured, PixelFormat kFormat>() __attribute__((always_inline)) {
    return narrow ? shade_preview<kTextured, kFormat, true>(t) : shade_preview<kTextured, kFormat, false>(t);
  });
}

}  // namespace gpubridge::sim
