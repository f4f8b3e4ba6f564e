#pragma once
// Register frames for converted triangles and render state. Field positions come from the
// register table in protocol/ (never hard-coded here).
#include <cstdint>
#include <span>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/geometry/convert.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::geometry {

// Appends COLOR, [TEXCOORD,] VERTEX for each vertex (TEXCOORD only when `textured`: S/T are not
// used otherwise). With PRIM.TYPE = LIST, the third VERTEX kicks the triangle.
void encode_triangle(const DeviceTriangle& tri, bool textured, std::vector<protocol::Frame>& out);

// Render state as the TRI_MODE fields.
struct RenderState {
  bool gouraud = true;
  bool textured = false;
  bool z_test = false;
  protocol::DepthFunc z_func = protocol::DepthFunc::Less;
  bool z_write = false;
  protocol::BlendMode blend = protocol::BlendMode::Off;
  bool dither = false;
  bool temporal = false;        // with dither: temporal dither (CAPS.FEATURES bit 6, protocol 1.1)
  unsigned dither_phase = 0;    // temporal dither phase: pass the frame number (its low four bits are sent with temporal only)
  bool mask_r = false, mask_g = false, mask_b = false, mask_a = false;
  bool tex_decal = false;
  friend bool operator==(const RenderState&, const RenderState&) = default;
};
std::uint64_t tri_mode_word(const RenderState& s);

// Texture description as TEX_FMT fields. width/height must be powers of two in 8..1024.
struct TextureFormat {
  unsigned width = 8, height = 8;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  protocol::Wrap wrap_s = protocol::Wrap::Repeat;
  protocol::Wrap wrap_t = protocol::Wrap::Repeat;
  bool bilinear = false;
  bool operator==(const TextureFormat&) const = default;
};
Result<std::uint64_t> tex_fmt_word(const TextureFormat& t);

// 16-byte aligned address registers (TEX_BASE, FB_DRAW, FB_DISPLAY, FB_Z).
Result<std::uint64_t> address16_word(std::uint64_t byte_address);
// FB_FORMAT from size and format (1..1024 each).
Result<std::uint64_t> fb_format_word(unsigned width, unsigned height, protocol::PixelFormat f);
// SCISSOR [x0, x1) x [y0, y1), each 0..1024.
Result<std::uint64_t> scissor_word(unsigned x0, unsigned y0, unsigned x1, unsigned y1);

// MEM_ADDR + MEM_DATA frames writing `bytes` at `address` (8-byte aligned; the tail is padded
// with zeros to a whole 8-byte word).
Result<void> encode_upload(std::uint32_t address, std::span<const std::uint8_t> bytes, std::vector<protocol::Frame>& out);

}  // namespace gpubridge::geometry
