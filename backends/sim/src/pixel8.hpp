#pragma once
// The pixel stage of both vector routines (span_simd.cpp, narrow_simd.cpp) for eight lanes, in
// section 11's order: depth test and Z write, the colour (flat, Gouraud or textured), blend, write
// mask and store in the buffer's format. Internal to those routines' .cpp files: it is inlined into
// their target clones.
#include <cstdint>

#include "color_lanes.hpp"
#include "pixel_lanes.hpp"
#include "simd_lanes.hpp"
#include "texture8.hpp"

namespace gpubridge::sim::simd {

// How the caller's chunks fall. A span's chunks of eight mostly pass or fail whole (long rows,
// coherent depth), so `Chunk::Span` checks: a chunk that fails whole touches nothing after the
// depth read, and one that passes whole stores its colour without reading it. A small triangle's
// box rows rarely do, and a branch on it would mispredict: `Chunk::Row` merges every row.
enum class Chunk { Span, Row };

// The draw's decisions that do not change from chunk to chunk. The routines compute them once,
// before their loops, so that the compiler can unswitch the loops on them (read from PixelLanes
// inside the loop they cost the 50,000-px spans a third of their speed).
struct StageFlags {
  bool depth = false;        // depth test or Z write
  bool reads_color = false;  // blend or write mask: the stored pixels matter even in passing lanes
};
[[gnu::always_inline]] inline StageFlags stage_flags(const PixelLanes& px) {
  return {px.z_test || px.z_write, px.blend != protocol::BlendMode::Off || px.keep != 0};
}

// Eight pixels: colour at cp, depth at zp (when the draw tests or writes depth); lanes 0..n-1
// are pixels and `pass` holds the covered ones among them; `whole` as for load_words; q the
// lanes' planes (R, G, B, A when gouraud, Z when depth, S, T, Q when textured); `bayer` the lanes'
// dither threshold indices (packed formats). Returns the lanes that passed the depth test.
// kTexelLanes (the preview path): q[5] and q[6] hold the texel coordinates themselves.
// V: u32x8, or u32x16 for untextured RGBA8888 spans (the span routine's AVX-512 instance); kMasked:
// tails through AVX-512's masked moves (load_words); kAvx2 (the span routine's instances with AVX2 or
// AVX-512): the depth words' byte order by one byte shuffle (bswap) and a chunk's pass mask as lane
// bits (lane_bits: one vmovmskps where four extracts, ors and ands were). kAvx512 (the span
// routine's AVX-512 instances): texture8's lanes (texture8_wide.hpp).
template <bool kTextured, PixelFormat kFormat, Chunk kChunk, bool kTexelLanes = false, bool kMasked = false,
          bool kAvx2 = false, bool kAvx512 = false, class V>
[[gnu::always_inline]] inline V pixel8(const PixelLanes& px, StageFlags f, const V* q, V pass, std::uint8_t* cp,
                                       std::uint8_t* zp, unsigned n, bool whole, V bayer) {
  using S = signed_lanes<V>;
  bool none = false, all = n == kLanesOf<V>;
  // A chunk that loaded whole (the row has room for every lane) stores every lane: the lanes beyond
  // n write back the words just loaded from the same addresses (same row, so the same band and
  // thread, and nothing writes them in between), one vector store where n words were a call to
  // memcpy. Not with masked loads (those lanes hold 0) nor on the preview path (kTexelLanes).
  const unsigned stored = !kMasked && !kTexelLanes && whole ? kLanesOf<V> : n;
  if (f.depth) {
    const V z = q[4] & px.zmask;
    const V old = load_words<V, kMasked>(zp, n, whole);  // lanes beyond n are masked off
    if (px.z_test) pass = depth_test(px.z_func, pass, (S)z, (S)(bswap<kAvx2>(old) & 0xFFFFFFu));  // both < 2^24
    if constexpr (kChunk == Chunk::Span && kAvx2 && kLanesOf<V> == 8) {
      const unsigned bits = lane_bits(&pass);
      none = bits == 0;
      all = all && bits == 0xFFu;
    } else if constexpr (kChunk == Chunk::Span) {
      constexpr unsigned kWords = sizeof(V) / 8;
      std::uint64_t m[kWords];
      std::memcpy(m, &pass, sizeof m);
      std::uint64_t any = 0, every = ~std::uint64_t{0};
      for (unsigned w = 0; w < kWords; ++w) {
        any |= m[w];
        every &= m[w];
      }
      none = any == 0;
      all = all && every == ~std::uint64_t{0};
    }
    if (px.z_write && !none) store_words<kMasked>(zp, (bswap<kAvx2>(z) & pass) | (old & ~pass), stored);
  }
  if (none) return pass;  // rejected chunks touch no colour
  V word = V{} + px.flat;
  if (px.gouraud) word = (q[0] & 255u) | ((q[1] & 255u) << 8) | ((q[2] & 255u) << 16) | (q[3] << 24);
  if constexpr (kTextured && kTexelLanes) word = texture8_lanes(px.texture, q[5], q[6], pass, n, word);
  else if constexpr (kTextured) word = texture8<kAvx512>(px.texture, q[5], q[6], q[7], pass, n, word);
  if (kChunk == Chunk::Span && all && !f.reads_color) {  // a fully passing chunk of a plain store: no read
    store_color<kFormat, kMasked>(cp, pack_color<kFormat>(word, bayer, px.temporal), kLanesOf<V>);
    return pass;
  }
  write_color8<kFormat, kMasked>(cp, n, stored, word, pass, px.blend, bayer, px.temporal, px.keep, whole);
  return pass;
}

// The routine instance for the draw's colour buffer format and texture: `routine` is a lambda
// template <bool kTextured, PixelFormat kFormat>, marked always_inline like every helper here, so
// that each instance inlines into the caller's target clone. The one place where a draw's modes
// become template parameters.
template <class Routine>
[[gnu::always_inline]] inline auto dispatch(const PixelLanes& px, const Routine& routine) {
  const bool textured = px.texture.tex != nullptr;
  switch (px.format) {
    case PixelFormat::RGB565:
      return textured ? routine.template operator()<true, PixelFormat::RGB565>()
                      : routine.template operator()<false, PixelFormat::RGB565>();
    case PixelFormat::RGBA2222:
      return textured ? routine.template operator()<true, PixelFormat::RGBA2222>()
                      : routine.template operator()<false, PixelFormat::RGBA2222>();
    case PixelFormat::RGBA8888: break;
  }
  return textured ? routine.template operator()<true, PixelFormat::RGBA8888>()
                  : routine.template operator()<false, PixelFormat::RGBA8888>();
}

}  // namespace gpubridge::sim::simd
