#include "preview_plain.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <immintrin.h>

#include "bilinear_wide.hpp"
#include "cpu_features.hpp"
#include "hier_z.hpp"
#include "setup.hpp"
#include "simd_lanes.hpp"

namespace gpubridge::sim {

bool preview_plain_applies(const DrawState& st) {
  using protocol::DepthFunc;
  if (st.fb_format != protocol::PixelFormat::RGBA8888 || st.keep_bits != 0) return false;
  if (st.textured && st.tex.format != protocol::PixelFormat::RGBA8888) return false;
  if (st.blend != protocol::BlendMode::Off && st.blend != protocol::BlendMode::Alpha) return false;
  if (!st.z_test) return true;
  switch (st.z_func) {
    case DepthFunc::Less:
    case DepthFunc::LessEqual:
    case DepthFunc::Greater:
    case DepthFunc::GreaterEqual:
    case DepthFunc::Always: return true;
    default: return false;
  }
}

std::uint8_t preview_small_kernel(const DrawState& st) {
  using protocol::DepthFunc;
  if (st.textured || !st.preview_plain) return 0;
  unsigned z = 0;  // the order of kSmallKernels (preview_plain_kernel.inc)
  if (st.z_test) {
    switch (st.z_func) {
      case DepthFunc::Less: z = 1; break;
      case DepthFunc::LessEqual: z = 2; break;
      case DepthFunc::Greater: z = 3; break;
      case DepthFunc::GreaterEqual: z = 4; break;
      default: z = 5; break;  // ALWAYS (preview_plain_applies admits no other)
    }
  } else if (st.z_write) {
    z = 5;  // written, not tested: ALWAYS
  }
  return static_cast<std::uint8_t>(1 + 2 * z + (st.blend == protocol::BlendMode::Alpha ? 1 : 0));
}

// The kernel twice: for AVX2 and for the baseline, picked once per process.
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace plain_avx2 {
#define PREVIEW_PLAIN_AVX2 1
#define PREVIEW_PLAIN_AVX512 0
#include "preview_plain_kernel.inc"
#undef PREVIEW_PLAIN_AVX512
#undef PREVIEW_PLAIN_AVX2
}  // namespace plain_avx2
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

// A third time for AVX-512 (VL, BW, DQ) in 256-bit vectors, used for the small triangles' setup
// and row kernel: 32 vector registers (the row kernel's lanes and constants no longer spill) and
// masked moves; the same integers again. Its wide rows of untextured draws also step in chunks of
// 16 pixels in 512-bit vectors (PREVIEW_PLAIN_AVX512: span16 in preview_plain_kernel.inc).
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,avx512f,avx512vl,avx512bw,avx512dq")
#endif
namespace plain_avx512 {
#define PREVIEW_PLAIN_AVX2 1
#define PREVIEW_PLAIN_AVX512 1
#include "preview_plain_kernel.inc"
#undef PREVIEW_PLAIN_AVX512
#undef PREVIEW_PLAIN_AVX2
}  // namespace plain_avx512
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

namespace plain_baseline {
#define PREVIEW_PLAIN_AVX2 0
#define PREVIEW_PLAIN_AVX512 0
#include "preview_plain_kernel.inc"
#undef PREVIEW_PLAIN_AVX512
#undef PREVIEW_PLAIN_AVX2
}  // namespace plain_baseline

namespace {
const SmallKernel* small_kernel_table() {
  return cpu_has_avx512() ? plain_avx512::kSmallKernels : cpu_has_avx2() ? plain_avx2::kSmallKernels : plain_baseline::kSmallKernels;
}
}  // namespace

namespace {
// One instance of a routine compiled three times (isa 0 the baseline, 1 AVX2, 2 AVX-512), null where
// this CPU cannot run it: for the tests that compare the instances' results.
template <class F>
F pick_instance(unsigned isa, F baseline, F avx2, F avx512) {
  switch (isa) {
    case 0: return baseline;
    case 1: return cpu_has_avx2() ? avx2 : nullptr;
    case 2: return cpu_has_avx512() ? avx512 : nullptr;
    default: return nullptr;
  }
}

// Whether a triangle's spans are 8 pixels or more on average (its area over its height; 16 before
// sim-rzrow, when a span's last count % 16 pixels took 8-lane chunks and the AVX-512 instance had
// no LaneWalk): twice
// the area is |ex0·ey1 − ex1·ey0| / 2^16 pixels (ex = −16·dy, ey = 16·dx in 1/16 pixel) and the
// height max |ex| / 2^8 pixels. In double: any edge steps, no overflow.
bool wide_spans(const PreviewPlain& t) {
  const double cross = std::fabs(static_cast<double>(t.ex[0]) * static_cast<double>(t.ey[1]) -
                                 static_cast<double>(t.ex[1]) * static_cast<double>(t.ey[0]));
  double height = 0;
  for (int i = 0; i < 3; ++i) height = std::max(height, std::fabs(static_cast<double>(t.ex[i])));
  return cross >= 4096.0 * height;
}
}  // namespace

PreviewCounts shade_preview_plain(const PreviewPlain& t) {
  // The AVX-512 instance (its chunks of 16, the last one masked) for untextured triangles whose
  // spans are 8 pixels or more on average; the AVX2 one otherwise: the thin triangles of the fan
  // scene (boxes wider than 16, spans mostly shorter) were 16 % slower in the AVX-512 instance
  // (15.8 against 13.6 ms, before its masked last chunk and lanes; at 4 pixels the fan read the
  // same to 5 % slower, sim-rzrow).
  // Textured draws take the AVX-512 instance whatever their shape: their chunks are the same 8
  // lanes, but its 32 vector registers keep the texture stage's lanes and constants, which the
  // AVX2 instance's 16 spill and reload in every chunk (sim-preview14).
  if (cpu_has_avx512() && (t.tex.texels || (t.width >= 16 && wide_spans(t)))) return plain_avx512::shade(t);
  return cpu_has_avx2() ? plain_avx2::shade(t) : plain_baseline::shade(t);
}

ShadeRoutine shade_instance(unsigned isa) {
  return pick_instance<ShadeRoutine>(isa, &plain_baseline::shade, &plain_avx2::shade, &plain_avx512::shade);
}

ShadeRoutine dividing_shade_instance(unsigned isa) {
  return pick_instance<ShadeRoutine>(isa, &plain_baseline::shade_dividing, &plain_avx2::shade_dividing,
                                     &plain_avx512::shade_dividing);
}

SmallSetup setup_small_preview(const Vertex& a, const Vertex& b, const Vertex& c, const DrawState& st,
                               unsigned subpixel_bits, SmallTriangle& t) {
  return small_setup_routine()(a, b, c, st, subpixel_bits, t);
}

SmallSetupRoutine small_setup_routine() {
  return cpu_has_avx512() ? &plain_avx512::setup_small : cpu_has_avx2() ? &plain_avx2::setup_small : &plain_baseline::setup_small;
}

SmallSetupRoutine small_setup_instance(unsigned isa) {
  return pick_instance<SmallSetupRoutine>(isa, &plain_baseline::setup_small, &plain_avx2::setup_small, &plain_avx512::setup_small);
}

BandCount band_count_instance(unsigned isa) {
  return pick_instance<BandCount>(isa, &plain_baseline::band_count, &plain_avx2::band_count, &plain_avx512::band_count);
}

SmallKernel small_kernel(const DrawState& st) { return small_kernel_table()[st.preview_small - 1]; }

}  // namespace gpubridge::sim
