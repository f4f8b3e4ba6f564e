#pragma once
// The texture unit (docs/protocol.md section 10): texel coordinates from (s, t, q) through the
// reciprocal unit, addressing, nearest / bilinear filtering, and the colour combine.
#include <cstdint>

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
inline TexelCoords texel_coords(std::int32_t s, std::int32_t t, Reciprocal rc, unsigned wl, unsigned hl) {
  const std::int64_t y = rc.y;
  return {(std::int64_t{s} * y) >> (43 - rc.n - wl), (std::int64_t{t} * y) >> (43 - rc.n - hl)};
}

// Section 10.3: the index a wrap mode uses for integer texel index i of a size-2^log2 axis.
inline std::int64_t address(std::int64_t i, protocol::Wrap mode, unsigned log2) {
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

class TextureUnit {
 public:
  TextureUnit(const TextureState& tex, const VideoMemory& mem) : tex_(tex), mem_(mem) {}

  // Filtered texel at texel coordinates (tu, tv); sets ERR_MEM_RANGE in errors for fetches beyond VRAM.
  protocol::Rgba8 sample(TexelCoords c, std::uint16_t& errors) const {
    if (!tex_.bilinear) return fetch(c.tu >> 12, c.tv >> 12, errors);
    const std::int64_t u = c.tu - 2048, v = c.tv - 2048;
    const std::int64_t i0 = u >> 12, j0 = v >> 12;
    const unsigned fu = static_cast<unsigned>((u >> 4) & 255), fv = static_cast<unsigned>((v >> 4) & 255);
    const protocol::Rgba8 c00 = fetch(i0, j0, errors), c10 = fetch(i0 + 1, j0, errors);
    const protocol::Rgba8 c01 = fetch(i0, j0 + 1, errors), c11 = fetch(i0 + 1, j0 + 1, errors);
    const unsigned w00 = (256 - fu) * (256 - fv), w10 = fu * (256 - fv), w01 = (256 - fu) * fv, w11 = fu * fv;
    auto mix = [&](std::uint8_t a, std::uint8_t b, std::uint8_t cc, std::uint8_t d) {
      return static_cast<std::uint8_t>((a * w00 + b * w10 + cc * w01 + d * w11 + 32768) >> 16);
    };
    return {mix(c00.r, c10.r, c01.r, c11.r), mix(c00.g, c10.g, c01.g, c11.g), mix(c00.b, c10.b, c01.b, c11.b),
            mix(c00.a, c10.a, c01.a, c11.a)};
  }

  // Texel (i, j) after addressing, expanded to 8 bits per channel.
  protocol::Rgba8 fetch(std::int64_t i, std::int64_t j, std::uint16_t& errors) const {
    const std::uint64_t ai = static_cast<std::uint64_t>(address(i, tex_.wrap_s, tex_.wl));
    const std::uint64_t aj = static_cast<std::uint64_t>(address(j, tex_.wrap_t, tex_.hl));
    const unsigned bpp = protocol::bytes_per_pixel(tex_.format);
    const std::uint64_t at = tex_.base + ((aj << tex_.wl) + ai) * bpp;
    if (tex_.in_vram) return protocol::load_pixel(tex_.format, mem_.data() + at);
    std::uint8_t buf[4];
    if (!mem_.read(at, buf, bpp)) errors |= protocol::ERR_MEM_RANGE;
    return protocol::load_pixel(tex_.format, buf);
  }

 private:
  const TextureState& tex_;
  const VideoMemory& mem_;
};

// Section 10.5.
inline protocol::Rgba8 combine(protocol::Rgba8 texel, protocol::Rgba8 colour, bool decal) {
  if (decal) return texel;
  return {static_cast<std::uint8_t>(div255(texel.r * colour.r)), static_cast<std::uint8_t>(div255(texel.g * colour.g)),
          static_cast<std::uint8_t>(div255(texel.b * colour.b)), static_cast<std::uint8_t>(div255(texel.a * colour.a))};
}

}  // namespace gpubridge::sim
