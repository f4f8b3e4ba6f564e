#pragma once
// What the vector routines' pixel stage (pixel8.hpp: depth test, Z write, texture, blend, write
// mask, colour store) needs of a draw: the same for the span routine and the small-triangle one.
#include <cstdint>

#include "gpubridge/protocol/registers.hpp"
#include "texture_lanes.hpp"

namespace gpubridge::sim {

struct PixelLanes {
  std::uint32_t flat = 0;      // colour word (memory order R,G,B,A) when !gouraud
  std::uint32_t zmask = 0xFFFFFF;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;  // of the colour buffer
  protocol::DepthFunc z_func = protocol::DepthFunc::Never;
  protocol::BlendMode blend = protocol::BlendMode::Off;
  std::uint32_t keep = 0;      // the stored bits of a pixel that the write mask keeps
  bool temporal = false;       // packed formats: the temporal quantiser (section 11) on the dither indices
  bool gouraud = false, z_test = false, z_write = false;
  // Texture stage (texture.tex == nullptr: untextured). Texels are fetched lane by lane (the texel
  // coordinates need 64-bit products and a table lookup); filter and combine run in lanes.
  TextureLanes texture;
};

}  // namespace gpubridge::sim
