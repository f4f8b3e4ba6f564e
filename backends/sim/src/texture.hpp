#pragma once
// The texture unit (docs/protocol.md section 10): texel coordinates from (s, t, q) through the
// reciprocal unit, addressing, nearest / bilinear filtering, and the colour combine.
#include <cstdint>
#include <cstring>

#include "draw_state.hpp"
#include "fixed_point.hpp"
#include "gpubridge/protocol/pixel.hpp"
#include "reciprocal.hpp"
#include "video_memory.hpp"

namespace gpubridge::sim {

struct TexelCoords {
  std::int64_t tu = 0, tv = 0;  // 1/4096-texel units
};

// Section 10.2 for one (s, t, q), given the reciprocal of q (q != 0).
[[gnu::always_inline]] inline TexelCoords texel_coords(std::int32_t s, std::int32_t t, Reciprocal rc, unsigned wl, unsigned hl) {
  const std::int64_t y = rc.y;
  return {(std::int64_t{s} * y) >> (43 - rc.n - wl), (std::int64_t{t} * y) >> (43 - rc.n - hl)};
}

// Section 10.3: the index a wrap mode uses for integer texel index i of a size-2^log2 axis.
[[gnu::always_inline]] inline std::int64_t address(std::int64_t i, protocol::Wrap mode, unsigned log2) {
  const std::int64_t size = std::int64_t{1} << log2;
  switch (mode) {
    case protocol::Wrap::Clamp: return i < 0 ? 0 : i >= size ? size - 1 : i;
    case protocol::Wrap::Mirror: {
      const std::int64_t k = i & (2 * size - 1);
      return k < size ? k : 2 * size - 1 - k;
    }
    default: return i & (size - 1);
  }
}

// Holds the draw's texture state by value (with the base pointer resolved once), so the per-pixel
// path reads no state through references that the framebuffer's byte stores could alias.
class TextureUnit {
 public:
  TextureUnit(const TextureState& tex, const VideoMemory& mem)
      : mem_(mem),
        base_(tex.base),
        direct_(tex.in_vram ? mem.data() + tex.base : nullptr),
        wl_(tex.wl),
        hl_(tex.hl),
        bpp_(protocol::bytes_per_pixel(tex.format)),
        format_(tex.format),
        wrap_s_(tex.wrap_s),
        wrap_t_(tex.wrap_t),
        bilinear_(tex.bilinear),
        wmask_((std::uint64_t{1} << tex.wl) - 1),
        hmask_((std::uint64_t{1} << tex.hl) - 1),
        rgba_repeat_(bilinear_ && direct_ != nullptr && format_ == protocol::PixelFormat::RGBA8888 &&
                     wrap_s_ == protocol::Wrap::Repeat && wrap_t_ == protocol::Wrap::Repeat) {}

  // Filtered texel at texel coordinates (tu, tv); sets ERR_MEM_RANGE in errors for fetches beyond VRAM.
  [[gnu::always_inline]] protocol::Rgba8 sample(TexelCoords c, std::uint16_t& errors) const {
    if (!bilinear_) return fetch(address(c.tu >> 12, wrap_s_, wl_), address(c.tv >> 12, wrap_t_, hl_), errors);
    const std::int64_t u = c.tu - 2048, v = c.tv - 2048;
    const std::int64_t i0 = u >> 12, j0 = v >> 12;
    const unsigned fu = static_cast<unsigned>((u >> 4) & 255), fv = static_cast<unsigned>((v >> 4) & 255);
    // Each axis is addressed once per neighbour, not once per texel.
    const std::int64_t a0 = address(i0, wrap_s_, wl_), a1 = address(i0 + 1, wrap_s_, wl_);
    const std::int64_t b0 = address(j0, wrap_t_, hl_), b1 = address(j0 + 1, wrap_t_, hl_);
    const protocol::Rgba8 c00 = fetch(a0, b0, errors), c10 = fetch(a1, b0, errors);
    const protocol::Rgba8 c01 = fetch(a0, b1, errors), c11 = fetch(a1, b1, errors);
    const unsigned w00 = (256 - fu) * (256 - fv), w10 = fu * (256 - fv), w01 = (256 - fu) * fv, w11 = fu * fv;
    auto mix = [&](std::uint8_t a, std::uint8_t b, std::uint8_t cc, std::uint8_t d) {
      return static_cast<std::uint8_t>((a * w00 + b * w10 + cc * w01 + d * w11 + 32768) >> 16);
    };
    return {mix(c00.r, c10.r, c01.r, c11.r), mix(c00.g, c10.g, c01.g, c11.g), mix(c00.b, c10.b, c01.b, c11.b),
            mix(c00.a, c10.a, c01.a, c11.a)};
  }

  // The texels sample() filters, for the vector routines: the four neighbours as colour words
  // (byte c = channel c: R, G, B, A, as the framebuffer stores them) and the bilinear weights
  // (nearest: c00 only, fu = fv = 0). The texture must lie inside VRAM (direct_).
  [[gnu::always_inline]] void quad(TexelCoords c, std::uint32_t& c00, std::uint32_t& c10, std::uint32_t& c01,
                                   std::uint32_t& c11, std::uint32_t& fu, std::uint32_t& fv) const {
    if (!bilinear_) {
      c00 = word(address(c.tu >> 12, wrap_s_, wl_), address(c.tv >> 12, wrap_t_, hl_));
      c10 = c01 = c11 = fu = fv = 0;
      return;
    }
    const std::int64_t u = c.tu - 2048, v = c.tv - 2048;
    const std::int64_t i0 = u >> 12, j0 = v >> 12;
    fu = static_cast<std::uint32_t>((u >> 4) & 255);
    fv = static_cast<std::uint32_t>((v >> 4) & 255);
    const std::int64_t a0 = address(i0, wrap_s_, wl_), a1 = address(i0 + 1, wrap_s_, wl_);
    const std::int64_t b0 = address(j0, wrap_t_, hl_), b1 = address(j0 + 1, wrap_t_, hl_);
    c00 = word(a0, b0);
    c10 = word(a1, b0);
    c01 = word(a0, b1);
    c11 = word(a1, b1);
  }
  // The common case of the exact path's textured spans, specialised (the bench's road and cubes):
  // an RGBA8888 bilinear texture inside VRAM that repeats on both axes. quad_rgba_repeat gives the
  // same words and weights as quad() without a wrap-mode switch, a format test and four multiplies
  // by the bytes per texel in every lane.
  bool bilinear_rgba_repeat() const { return rgba_repeat_; }
  [[gnu::always_inline]] void quad_rgba_repeat(TexelCoords c, std::uint32_t& c00, std::uint32_t& c10,
                                               std::uint32_t& c01, std::uint32_t& c11, std::uint32_t& fu,
                                               std::uint32_t& fv) const {
    const std::int64_t u = c.tu - 2048, v = c.tv - 2048;
    fu = static_cast<std::uint32_t>((u >> 4) & 255);
    fv = static_cast<std::uint32_t>((v >> 4) & 255);
    // Repeat: the index modulo the size, a mask of the two's-complement index (section 10.3).
    const std::uint64_t i0 = static_cast<std::uint64_t>(u >> 12), j0 = static_cast<std::uint64_t>(v >> 12);
    const std::uint64_t a0 = (i0 & wmask_) * 4, a1 = ((i0 + 1) & wmask_) * 4;
    const std::uint8_t* row0 = direct_ + ((j0 & hmask_) << (wl_ + 2));
    const std::uint8_t* row1 = direct_ + (((j0 + 1) & hmask_) << (wl_ + 2));
    std::memcpy(&c00, row0 + a0, 4);  // memory order R, G, B, A is already the word's byte order
    std::memcpy(&c10, row0 + a1, 4);
    std::memcpy(&c01, row1 + a0, 4);
    std::memcpy(&c11, row1 + a1, 4);
  }
  bool direct() const { return direct_ != nullptr; }
  bool bilinear() const { return bilinear_; }
  // What texture8_wide.hpp's lanes address with (an RGBA8888 repeat texture inside VRAM).
  const std::uint8_t* texels() const { return direct_; }
  unsigned wl() const { return wl_; }
  std::uint32_t wmask() const { return static_cast<std::uint32_t>(wmask_); }
  std::uint32_t hmask() const { return static_cast<std::uint32_t>(hmask_); }

  // Texel (i, j) of an addressed (in-range) index pair, expanded to 8 bits per channel.
  [[gnu::always_inline]] protocol::Rgba8 fetch(std::int64_t i, std::int64_t j, std::uint16_t& errors) const {
    const std::uint64_t offset = ((static_cast<std::uint64_t>(j) << wl_) + static_cast<std::uint64_t>(i)) * bpp_;
    if (direct_) {
      if (format_ == protocol::PixelFormat::RGBA8888) {  // inline: the generic decoder is a call per texel
        const std::uint8_t* p = direct_ + offset;
        return {p[0], p[1], p[2], p[3]};
      }
      return protocol::load_pixel(format_, direct_ + offset);
    }
    std::uint8_t buf[4];
    if (!mem_.read(std::uint64_t{base_} + offset, buf, bpp_)) errors |= protocol::ERR_MEM_RANGE;
    return protocol::load_pixel(format_, buf);
  }

 private:
  // Texel (i, j) as a colour word (byte c = channel c), from a texture inside VRAM.
  [[gnu::always_inline]] std::uint32_t word(std::int64_t i, std::int64_t j) const {
    const std::uint8_t* p = direct_ + ((static_cast<std::uint64_t>(j) << wl_) + static_cast<std::uint64_t>(i)) * bpp_;
    if (format_ == protocol::PixelFormat::RGBA8888) {  // memory order R, G, B, A is already the word's byte order
      std::uint32_t w;
      std::memcpy(&w, p, 4);
      return w;
    }
    const protocol::Rgba8 c = protocol::load_pixel(format_, p);
    return std::uint32_t{c.r} | (std::uint32_t{c.g} << 8) | (std::uint32_t{c.b} << 16) | (std::uint32_t{c.a} << 24);
  }

  const VideoMemory& mem_;
  std::uint32_t base_;
  const std::uint8_t* direct_;  // the texture's first byte when it lies wholly inside VRAM
  unsigned wl_, hl_, bpp_;
  protocol::PixelFormat format_;
  protocol::Wrap wrap_s_, wrap_t_;
  bool bilinear_;
  std::uint64_t wmask_, hmask_;  // size − 1 of each axis
  bool rgba_repeat_;  // quad_rgba_repeat applies (bilinear_rgba_repeat): fixed per draw, read per chunk
};

// Section 10.5.
inline protocol::Rgba8 combine(protocol::Rgba8 texel, protocol::Rgba8 color, bool decal) {
  if (decal) return texel;
  return {static_cast<std::uint8_t>(div255(texel.r * color.r)), static_cast<std::uint8_t>(div255(texel.g * color.g)),
          static_cast<std::uint8_t>(div255(texel.b * color.b)), static_cast<std::uint8_t>(div255(texel.a * color.a))};
}

}  // namespace gpubridge::sim
