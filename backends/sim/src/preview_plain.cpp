#include "preview_plain.hpp"

#include <cstring>

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

// The kernel twice: for AVX2 and for the baseline, picked once per process.
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace plain_avx2 {
#define PREVIEW_PLAIN_AVX2 1
#include "preview_plain_kernel.inc"
#undef PREVIEW_PLAIN_AVX2
}  // namespace plain_avx2
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

namespace plain_baseline {
#define PREVIEW_PLAIN_AVX2 0
#include "preview_plain_kernel.inc"
#undef PREVIEW_PLAIN_AVX2
}  // namespace plain_baseline

PreviewCounts shade_preview_plain(const PreviewPlain& t) {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2 ? plain_avx2::shade(t) : plain_baseline::shade(t);
}

}  // namespace gpubridge::sim
