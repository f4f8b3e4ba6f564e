#pragma once
// Pixel packing for the device's memory formats (docs/protocol.md, "Pixel formats"). All
// multi-byte device words are big-endian in memory. Expansion to 8 bits replicates the top bits.
#include <cstdint>

#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::protocol {

struct Rgba8 {
  std::uint8_t r = 0, g = 0, b = 0, a = 0;
  friend bool operator==(const Rgba8&, const Rgba8&) = default;
};

constexpr Rgba8 rgba_from_word(std::uint32_t w) {  // COLOR / CLEAR_COLOR layout 0xRRGGBBAA
  return {static_cast<std::uint8_t>(w >> 24), static_cast<std::uint8_t>(w >> 16), static_cast<std::uint8_t>(w >> 8),
          static_cast<std::uint8_t>(w)};
}
constexpr std::uint32_t word_from_rgba(Rgba8 c) {
  return (std::uint32_t{c.r} << 24) | (std::uint32_t{c.g} << 16) | (std::uint32_t{c.b} << 8) | c.a;
}

constexpr std::uint8_t expand5(unsigned v) { return static_cast<std::uint8_t>((v << 3) | (v >> 2)); }
constexpr std::uint8_t expand6(unsigned v) { return static_cast<std::uint8_t>((v << 2) | (v >> 4)); }
constexpr std::uint8_t expand2(unsigned v) { return static_cast<std::uint8_t>(v * 0x55); }

// Channel widths per format: {R, G, B, A}; A = 0 means alpha is not stored (reads as 255).
struct ChannelBits { std::uint8_t r, g, b, a; };
constexpr ChannelBits channel_bits(PixelFormat f) {
  switch (f) {
    case PixelFormat::RGB565: return {5, 6, 5, 0};
    case PixelFormat::RGBA2222: return {2, 2, 2, 2};
    default: return {8, 8, 8, 8};
  }
}

// Reads one pixel at p (bytes_per_pixel(f) bytes) and expands it to 8 bits per channel.
constexpr Rgba8 load_pixel(PixelFormat f, const std::uint8_t* p) {
  switch (f) {
    case PixelFormat::RGB565: {
      const unsigned v = (unsigned{p[0]} << 8) | p[1];
      return {expand5(v >> 11), expand6((v >> 5) & 63), expand5(v & 31), 255};
    }
    case PixelFormat::RGBA2222: {
      const unsigned v = p[0];
      return {expand2(v >> 6), expand2((v >> 4) & 3), expand2((v >> 2) & 3), expand2(v & 3)};
    }
    default: return {p[0], p[1], p[2], p[3]};
  }
}

// Stores already-quantised channel values (each < 2^bits of its channel) at p.
constexpr void store_quantised(PixelFormat f, std::uint8_t* p, unsigned r, unsigned g, unsigned b, unsigned a) {
  switch (f) {
    case PixelFormat::RGB565: {
      const unsigned v = (r << 11) | (g << 5) | b;
      p[0] = static_cast<std::uint8_t>(v >> 8);
      p[1] = static_cast<std::uint8_t>(v);
      break;
    }
    case PixelFormat::RGBA2222: p[0] = static_cast<std::uint8_t>((r << 6) | (g << 4) | (b << 2) | a); break;
    default:
      p[0] = static_cast<std::uint8_t>(r);
      p[1] = static_cast<std::uint8_t>(g);
      p[2] = static_cast<std::uint8_t>(b);
      p[3] = static_cast<std::uint8_t>(a);
  }
}

// Truncating store of an 8-bit colour (what CLEAR does; drawing may dither first).
constexpr void store_pixel(PixelFormat f, std::uint8_t* p, Rgba8 c) {
  const auto bits = channel_bits(f);
  store_quantised(f, p, c.r >> (8 - bits.r), c.g >> (8 - bits.g), c.b >> (8 - bits.b),
                  bits.a ? c.a >> (8 - bits.a) : 0);
}

}  // namespace gpubridge::protocol
