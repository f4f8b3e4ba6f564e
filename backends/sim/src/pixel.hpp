#pragma once
// The pixel pipeline's per-pixel operations (docs/protocol.md section 11): depth compare, blend,
// quantise + dither, write mask. The rasteriser calls them in section 11's order.
#include <cstdint>

#include "draw_state.hpp"
#include "fixed_point.hpp"
#include "gpubridge/protocol/pixel.hpp"

namespace gpubridge::sim {

inline bool depth_passes(protocol::DepthFunc f, std::uint32_t z, std::uint32_t d) {
  switch (f) {
    case protocol::DepthFunc::Less: return z < d;
    case protocol::DepthFunc::Equal: return z == d;
    case protocol::DepthFunc::LessEqual: return z <= d;
    case protocol::DepthFunc::Greater: return z > d;
    case protocol::DepthFunc::NotEqual: return z != d;
    case protocol::DepthFunc::GreaterEqual: return z >= d;
    case protocol::DepthFunc::Always: return true;
    default: return false;
  }
}

inline std::uint8_t blend_channel(protocol::BlendMode m, unsigned src, unsigned dst, unsigned alpha) {
  switch (m) {
    case protocol::BlendMode::Alpha: return static_cast<std::uint8_t>(div255(src * alpha + dst * (255 - alpha)));
    case protocol::BlendMode::Add: return static_cast<std::uint8_t>(src + dst > 255 ? 255 : src + dst);
    case protocol::BlendMode::Multiply: return static_cast<std::uint8_t>(div255(src * dst));
    default: return static_cast<std::uint8_t>(src);
  }
}

inline protocol::Rgba8 blend(protocol::BlendMode m, protocol::Rgba8 src, protocol::Rgba8 dst) {
  return {blend_channel(m, src.r, dst.r, src.a), blend_channel(m, src.g, dst.g, src.a),
          blend_channel(m, src.b, dst.b, src.a), blend_channel(m, src.a, dst.a, src.a)};
}

inline constexpr std::uint8_t kBayer4[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};

// Dither threshold index t (0..15) of screen position (x, y): the Bayer value, XOR the reversed
// phase in temporal mode. XOR with a constant permutes the 16 values, so every aligned 4x4 block
// of every frame still holds each threshold once.
inline unsigned dither_threshold(const DitherMode& d, int x, int y) { return kBayer4[y & 3][x & 3] ^ d.phase_xor; }

// Temporal quantiser: v scaled to the n-bit levels 0..M (M = 2^n - 1, g = M·v + (M·v >> 8), which
// is 256·M·v/255 within one unit and at most 256·M - 1), plus the centred threshold 16t + 8, over
// 256. Never above M, so no saturation; the mean over the 16 thresholds is g/256 within 1/32.
inline unsigned quantise_temporal(unsigned v, unsigned n, unsigned t) {
  const unsigned a = (v << n) - v;
  return (a + (a >> 8) + (t << 4) + 8) >> 8;
}

// 8-bit value v to an n-bit channel (n < 8), optionally dithered at screen position (x, y).
inline unsigned quantise(unsigned v, unsigned n, const DitherMode& d, int x, int y) {
  if (!d.on) return v >> (8 - n);
  const unsigned t = dither_threshold(d, x, y);
  if (d.temporal) return quantise_temporal(v, n, t);
  const unsigned add = (t << (8 - n)) >> 4;
  v = v + add > 255 ? 255 : v + add;
  return v >> (8 - n);
}

// Quantises (and dithers) c and stores it at p honouring the write mask (keep bit 0 R .. 3 A:
// 1 = keep the stored channel).
inline void store_color(protocol::PixelFormat f, std::uint8_t* p, protocol::Rgba8 c, const DitherMode& dither,
                         std::uint8_t keep, int x, int y) {
  using protocol::PixelFormat;
  switch (f) {
    case PixelFormat::RGB565: {
      const unsigned old = (unsigned{p[0]} << 8) | p[1];
      unsigned r = quantise(c.r, 5, dither, x, y), g = quantise(c.g, 6, dither, x, y), b = quantise(c.b, 5, dither, x, y);
      if (keep & 1) r = old >> 11;
      if (keep & 2) g = (old >> 5) & 63;
      if (keep & 4) b = old & 31;
      protocol::store_quantised(f, p, r, g, b, 0);
      break;
    }
    case PixelFormat::RGBA2222: {
      const unsigned old = p[0];
      unsigned ch[4] = {quantise(c.r, 2, dither, x, y), quantise(c.g, 2, dither, x, y), quantise(c.b, 2, dither, x, y),
                        quantise(c.a, 2, dither, x, y)};
      for (unsigned i = 0; i < 4; ++i)
        if (keep & (1u << i)) ch[i] = (old >> (6 - 2 * i)) & 3;
      protocol::store_quantised(f, p, ch[0], ch[1], ch[2], ch[3]);
      break;
    }
    default: {
      const std::uint8_t ch[4] = {c.r, c.g, c.b, c.a};
      for (unsigned i = 0; i < 4; ++i)
        if (!(keep & (1u << i))) p[i] = ch[i];
    }
  }
}

}  // namespace gpubridge::sim
