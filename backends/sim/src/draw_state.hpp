#pragma once
// The render state a triangle executes with, decoded once from TRI_MODE, TEX_*, FB_*, SCISSOR when
// one of them changes (not per triangle). Also the accuracy knobs that shape the arithmetic.
#include <cstdint>

#include "gpubridge/protocol/registers.hpp"
#include "gpubridge/sim/options.hpp"

namespace gpubridge::sim {

struct ClipRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) x [y0, y1); empty when x1 <= x0 or y1 <= y0
  bool empty() const { return x1 <= x0 || y1 <= y0; }
};

// TRI_MODE.DITHER, TEMPORAL and DITHER_PHASE as the quantiser uses them (pixel.hpp, section 11).
struct DitherMode {
  bool on = false;              // DITHER
  bool temporal = false;        // DITHER and TEMPORAL: thresholds B ^ phase_xor, levels scaled to 0..2^n - 1
  std::uint8_t phase_xor = 0;   // temporal: DITHER_PHASE with its four bits reversed; 0 otherwise
};

struct TextureState {
  std::uint32_t base = 0;
  unsigned wl = 3, hl = 3;  // log2 width / height
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  bool bilinear = false;
  protocol::Wrap wrap_s = protocol::Wrap::Repeat, wrap_t = protocol::Wrap::Repeat;
  bool in_vram = false;  // the whole texture lies inside video memory (unchecked fetches)
};

struct DrawState {
  // TRI_MODE
  bool gouraud = false, textured = false, z_test = false, z_write = false, decal = false;
  DitherMode dither;
  protocol::DepthFunc z_func = protocol::DepthFunc::Never;
  protocol::BlendMode blend = protocol::BlendMode::Off;
  std::uint8_t keep_mask = 0;  // bit 0 R, 1 G, 2 B, 3 A: 1 = channel keeps its stored bits
  // FB_*
  protocol::PixelFormat fb_format = protocol::PixelFormat::RGBA8888;
  unsigned fb_width = 640, fb_height = 480, bpp = 4;
  std::uint32_t fb_draw = 0, fb_z = 0;
  bool color_in_vram = false, z_in_vram = false;  // whole buffers inside memory
  ClipRect clip;  // scissor ∩ framebuffer
  TextureState tex;
  // Derived decisions (per draw specialisation).
  bool writes_nothing = false;   // Z_FUNC NEVER with the test on, or nothing writable
  bool reads_color = false;      // blend or a partial write mask needs the destination
  bool simple_color = false;     // RGBA8888, no blend, no mask: store the 4 bytes directly
  bool buffers_disjoint = false; // colour and depth buffers share no byte (pixel order between them is free)
  std::uint32_t keep_bits = 0;   // the stored bits of a pixel that the write mask keeps (RGBA8888: bytes, byte c = channel c)
  unsigned mode_class = 0;       // DeviceStats::by_mode index: the planes a gateware sets up and steps (timing only)
  // Bands can be drawn independently (the renderer's batches across threads): no buffer the draw
  // reads overlaps one it writes in another band (colour, depth and texture ranges do not alias).
  // Decided here once per state rather than per triangle.
  bool bands_independent = false;
  // `--accuracy preview` (decided once per state, not per triangle): whether the preview routine
  // can draw it (preview_applies), whether its plain kernel can (preview_plain_applies) and, for
  // its small triangles, the small-triangle kernel + 1 (preview_small_kernel, preview_plain.hpp;
  // 0: none).
  bool preview_ok = false;
  bool preview_plain = false;
  std::uint8_t preview_small = 0;
};

// Register indices into the device's register file.
struct RegisterValues {
  std::uint64_t tri_mode, tex_base, tex_fmt, scissor, fb_draw, fb_z, fb_format;
};
DrawState decode_draw_state(const RegisterValues& regs, std::uint64_t vram_bytes);

}  // namespace gpubridge::sim
