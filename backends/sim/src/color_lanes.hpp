#pragma once
// Section 11's colour write for eight pixels of the colour buffer in any format (RGBA8888 words,
// RGB565 big-endian halfwords, RGBA2222 bytes): blend against the stored pixels (packed ones
// expanded by bit replication), quantise packed formats with the lanes' ordered or temporal dither,
// keep the bits the write mask protects, store the passing lanes. Byte for byte what pixel.hpp's
// store_color() does per pixel (the vector equivalence tests compare them). Internal to the vector
// routines (pixel8.hpp): it is inlined into their target clones.
#include <cstdint>
#include <cstring>

#include "simd_lanes.hpp"

namespace gpubridge::sim::simd {

using protocol::PixelFormat;

typedef std::uint16_t u16x8 __attribute__((vector_size(16)));
typedef std::uint8_t u8x8 __attribute__((vector_size(8)));

// The first n stored pixels at p as lanes (packed formats: the stored bits, byte-swapped to host
// order); later lanes hold the next pixels of the row when `whole` (eight pixels fit before the row
// ends), else 0. Eight pixels are copied with a constant size, which becomes one load: a copy of n
// bytes is a call, or pieces that the vector load cannot forward from.
// kMasked, V: as for load_words (16 lanes: RGBA8888 only).
template <PixelFormat kFormat, class V = u32x8, bool kMasked = false>
[[gnu::always_inline]] inline V load_color(const std::uint8_t* p, unsigned n, bool whole) {
  if constexpr (kFormat == PixelFormat::RGBA8888) {
    return load_words<V, kMasked>(p, n, whole);
  } else if constexpr (kFormat == PixelFormat::RGB565) {
    u16x8 h = {};
    if (n == 8 || whole) std::memcpy(&h, p, 16);
    else std::memcpy(&h, p, std::size_t{n} * 2);
    const u32x8 v = __builtin_convertvector(h, u32x8);
    return ((v & 0xFFu) << 8) | (v >> 8);  // big-endian in video memory
  } else {
    u8x8 b = {};
    if (n == 8 || whole) std::memcpy(&b, p, 8);
    else std::memcpy(&b, p, n);
    return __builtin_convertvector(b, u32x8);
  }
}

template <PixelFormat kFormat, bool kMasked = false, class V>
[[gnu::always_inline]] inline void store_color(std::uint8_t* p, V v, unsigned n) {
  if constexpr (kFormat == PixelFormat::RGBA8888) {
    store_words<kMasked>(p, v, n);
  } else if constexpr (kFormat == PixelFormat::RGB565) {
    const u16x8 h = __builtin_convertvector(((v & 0xFFu) << 8) | ((v >> 8) & 0xFFu), u16x8);
    if (n == 8) std::memcpy(p, &h, 16);
    else std::memcpy(p, &h, std::size_t{n} * 2);
  } else {
    const u8x8 b = __builtin_convertvector(v, u8x8);
    if (n == 8) std::memcpy(p, &b, 8);
    else std::memcpy(p, &b, n);
  }
}

// Stored pixels as colour words (byte c = channel c), packed channels widened by bit replication.
template <PixelFormat kFormat, class V>
[[gnu::always_inline]] inline V expand_color(V v) {
  if constexpr (kFormat == PixelFormat::RGBA8888) {
    return v;
  } else if constexpr (kFormat == PixelFormat::RGB565) {
    const V r = v >> 11, g = (v >> 5) & 63u, b = v & 31u;
    return ((r << 3) | (r >> 2)) | (((g << 2) | (g >> 4)) << 8) | (((b << 3) | (b >> 2)) << 16) | (255u << 24);
  } else {
    return ((v >> 6) & 3u) * 0x55u | (((v >> 4) & 3u) * 0x55u) << 8 | (((v >> 2) & 3u) * 0x55u) << 16 |
           ((v & 3u) * 0x55u) << 24;
  }
}

// 8-bit channel c of `word` to n bits after adding the dither offset (saturating at 255).
template <class V>
[[gnu::always_inline]] inline V quantise8(V word, unsigned c, unsigned n, V add) {
  V v = ((word >> c) & 255u) + add;
  const V over = mask(v > 255u);
  v = (v & ~over) | (255u & over);
  return v >> (8 - n);
}

// Temporal quantiser of channel c to n bits (pixel.hpp's quantise_temporal): `t16` holds each
// lane's 16t + 8.
template <class V>
[[gnu::always_inline]] inline V quantise_temporal8(V word, unsigned c, unsigned n, V t16) {
  const V v = (word >> c) & 255u;
  const V a = (v << n) - v;
  return (a + (a >> 8) + t16) >> 8;
}

// Channel c (bit offset in the word) of the lanes to n bits, with the lanes' threshold index t:
// the ordered dither adds (t << (8 - n)) >> 4 (saturating) and truncates; the temporal one
// quantises with the centred threshold 16t + 8.
template <bool kTemporal, class V>
[[gnu::always_inline]] inline V quantise_lanes(V word, unsigned c, unsigned n, V bayer) {
  if constexpr (kTemporal) return quantise_temporal8(word, c, n, (bayer << 4) + 8u);
  else return quantise8(word, c, n, (bayer << (8 - n)) >> 4);
}

// Colour words to packed pixels (one channel layout per format, either quantiser).
template <PixelFormat kFormat, bool kTemporal, class V>
[[gnu::always_inline]] inline V pack_channels(V w, V t) {
  if constexpr (kFormat == PixelFormat::RGB565)
    return (quantise_lanes<kTemporal>(w, 0, 5, t) << 11) | (quantise_lanes<kTemporal>(w, 8, 6, t) << 5) |
           quantise_lanes<kTemporal>(w, 16, 5, t);
  else
    return (quantise_lanes<kTemporal>(w, 0, 2, t) << 6) | (quantise_lanes<kTemporal>(w, 8, 2, t) << 4) |
           (quantise_lanes<kTemporal>(w, 16, 2, t) << 2) | quantise_lanes<kTemporal>(w, 24, 2, t);
}
// Colour words to stored pixels. `bayer` holds each lane's threshold index t (0 without dither);
// `temporal` selects the temporal dither's quantiser. RGBA8888 stores the words as they are.
template <PixelFormat kFormat, class V>
[[gnu::always_inline]] inline V pack_color(V word, V bayer, bool temporal) {
  if constexpr (kFormat == PixelFormat::RGBA8888) return word;
  else return temporal ? pack_channels<kFormat, true>(word, bayer) : pack_channels<kFormat, false>(word, bayer);
}

// The colour write of n pixels at p merged with the stored ones: blend (`mode`), the bits the
// write mask keeps (`keep_bits`) and the lanes that do not pass keep what is stored. `whole`: as
// for load_color; `stored` (n, or every lane when `whole`) pixels are written back.
template <PixelFormat kFormat, bool kMasked = false, class V>
[[gnu::always_inline]] inline void write_color8(std::uint8_t* p, unsigned n, unsigned stored, V word, V pass,
                                                protocol::BlendMode mode, V bayer, bool temporal,
                                                std::uint32_t keep_bits, bool whole) {
  const V old = load_color<kFormat, V, kMasked>(p, n, whole);
  if (mode != protocol::BlendMode::Off) word = blend(mode, word, expand_color<kFormat>(old));
  V out = pack_color<kFormat>(word, bayer, temporal);
  out = (out & ~keep_bits) | (old & keep_bits);
  out = (out & pass) | (old & ~pass);
  store_color<kFormat, kMasked>(p, out, stored);
}

}  // namespace gpubridge::sim::simd
