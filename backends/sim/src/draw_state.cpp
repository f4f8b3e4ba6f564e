#include "draw_state.hpp"

#include <algorithm>

#include "preview_plain.hpp"
#include "rasterizer.hpp"

namespace gpubridge::sim {

using namespace protocol;

namespace {

// The stored bits of a pixel of format f that TRI_MODE's write mask keeps (RGBA8888: the bytes of
// the colour word, byte c = channel c).
std::uint32_t keep_bits_of(PixelFormat f, std::uint8_t keep_mask) {
  std::uint32_t bits = 0;
  if (f == PixelFormat::RGB565) {
    if (keep_mask & 1) bits |= 0xF800;
    if (keep_mask & 2) bits |= 0x07E0;
    if (keep_mask & 4) bits |= 0x001F;
  } else if (f == PixelFormat::RGBA2222) {
    for (unsigned c = 0; c < 4; ++c)
      if (keep_mask & (1u << c)) bits |= 3u << (6 - 2 * c);
  } else {
    for (unsigned c = 0; c < 4; ++c)
      if (keep_mask & (1u << c)) bits |= 0xFFu << (8 * c);
  }
  return bits;
}

bool overlaps(std::uint64_t a, std::uint64_t alen, std::uint64_t b, std::uint64_t blen) {
  return a < b + blen && b < a + alen;
}

}  // namespace

DrawState decode_draw_state(const RegisterValues& r, std::uint64_t vram_bytes) {
  DrawState s;
  const std::uint64_t m = r.tri_mode;
  s.gouraud = m & 1;
  s.textured = (m >> 1) & 1;
  s.z_test = (m >> 2) & 1;
  s.z_func = static_cast<DepthFunc>((m >> 3) & 7);
  s.z_write = (m >> 6) & 1;
  s.blend = static_cast<BlendMode>((m >> 7) & 3);
  s.dither.on = (m >> 9) & 1;
  s.keep_mask = static_cast<std::uint8_t>((m >> 10) & 15);
  s.decal = (m >> 14) & 1;
  s.dither.temporal = s.dither.on && ((m >> 15) & 1);
  if (s.dither.temporal) {
    const unsigned p = (m >> 16) & 15;
    s.dither.phase_xor = static_cast<std::uint8_t>(((p & 1) << 3) | ((p & 2) << 1) | ((p & 4) >> 1) | ((p & 8) >> 3));
  }

  s.fb_format = static_cast<PixelFormat>((r.fb_format >> 32) & 3);
  s.fb_width = std::max<unsigned>(1, r.fb_format & 0x7FF);
  s.fb_height = std::max<unsigned>(1, (r.fb_format >> 16) & 0x7FF);
  s.bpp = bytes_per_pixel(s.fb_format);
  s.fb_draw = static_cast<std::uint32_t>(r.fb_draw & 0xFFFFFFF0u);
  s.fb_z = static_cast<std::uint32_t>(r.fb_z & 0xFFFFFFF0u);
  const std::uint64_t pixels = std::uint64_t{s.fb_width} * s.fb_height;
  s.color_in_vram = s.fb_draw + pixels * s.bpp <= vram_bytes;
  s.z_in_vram = s.fb_z + pixels * 4 <= vram_bytes;

  const int sx0 = r.scissor & 0x7FF, sy0 = (r.scissor >> 16) & 0x7FF;
  const int sx1 = (r.scissor >> 32) & 0x7FF, sy1 = (r.scissor >> 48) & 0x7FF;
  s.clip = {std::max(0, sx0), std::max(0, sy0), std::min<int>(s.fb_width, sx1), std::min<int>(s.fb_height, sy1)};

  s.tex.base = static_cast<std::uint32_t>(r.tex_base & 0xFFFFFFF0u);
  s.tex.wl = std::clamp<unsigned>(r.tex_fmt & 15, kMinTextureLog2, kMaxTextureLog2);
  s.tex.hl = std::clamp<unsigned>((r.tex_fmt >> 4) & 15, kMinTextureLog2, kMaxTextureLog2);
  s.tex.wrap_s = static_cast<Wrap>((r.tex_fmt >> 8) & 3);
  s.tex.wrap_t = static_cast<Wrap>((r.tex_fmt >> 10) & 3);
  s.tex.bilinear = (r.tex_fmt >> 12) & 1;
  s.tex.format = static_cast<PixelFormat>((r.tex_fmt >> 16) & 3);
  s.tex.in_vram = s.tex.base + (std::uint64_t{1} << (s.tex.wl + s.tex.hl)) * bytes_per_pixel(s.tex.format) <= vram_bytes;

  // RGB565 stores no alpha: its alpha mask bit changes nothing.
  const std::uint8_t stored = s.fb_format == PixelFormat::RGB565 ? 0x7 : 0xF;
  const bool all_masked = (s.keep_mask & stored) == stored;
  const bool some_masked = (s.keep_mask & stored) != 0;
  s.writes_nothing = (s.z_test && s.z_func == DepthFunc::Never) || (all_masked && !s.z_write);
  s.reads_color = s.blend != BlendMode::Off || (some_masked && !all_masked && s.fb_format != PixelFormat::RGBA8888);
  const std::uint64_t clen = pixels * s.bpp, zlen = pixels * 4;
  s.buffers_disjoint = s.fb_draw + clen <= s.fb_z || s.fb_z + zlen <= s.fb_draw;
  s.simple_color = s.fb_format == PixelFormat::RGBA8888 && s.blend == BlendMode::Off && !some_masked;
  s.keep_bits = keep_bits_of(s.fb_format, s.keep_mask);
  // Timing class (section 19): colour planes only when a colour channel is written (the
  // gateware's setup skips them otherwise), Z for the test or the write, S/T/Q when textured.
  s.mode_class = ((s.gouraud && !all_masked) ? 1u : 0u) | ((s.z_test || s.z_write) ? 2u : 0u) |
                 ((s.textured && !all_masked) ? 4u : 0u);
  const bool depth = s.z_test || s.z_write;
  const std::uint64_t tlen = (std::uint64_t{1} << (s.tex.wl + s.tex.hl)) * bytes_per_pixel(s.tex.format);
  s.bands_independent = (!depth || !overlaps(s.fb_draw, clen, s.fb_z, zlen)) &&
                        (!s.textured || (!overlaps(s.tex.base, tlen, s.fb_draw, clen) &&
                                         (!depth || !overlaps(s.tex.base, tlen, s.fb_z, zlen))));
  s.preview_ok = preview_applies(s);
  s.preview_plain = s.preview_ok && preview_plain_applies(s);
  s.preview_small = s.preview_ok ? preview_small_kernel(s) : 0;
  return s;
}

}  // namespace gpubridge::sim
