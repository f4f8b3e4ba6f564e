#include "gpubridge/geometry/encode.hpp"

#include <bit>

#include <fmt/format.h>

namespace gpubridge::geometry {
namespace {

using protocol::Reg;

std::uint64_t put(Reg r, std::string_view field, std::uint64_t data, std::uint64_t value) {
  const protocol::Field* f = protocol::describe(r).field(field);
  return f ? f->put(data, value) : data;  // every name used here exists in the table (tested)
}

}  // namespace

void encode_triangle(const DeviceTriangle& tri, bool textured, std::vector<protocol::Frame>& out) {
  for (const auto& v : tri) {
    out.push_back(protocol::write_frame(Reg::COLOR, color_word(v)));
    if (textured) out.push_back(protocol::write_frame(Reg::TEXCOORD, texcoord_word(v)));
    out.push_back(protocol::write_frame(Reg::VERTEX, vertex_word(v)));
  }
}

std::uint64_t tri_mode_word(const RenderState& s) {
  std::uint64_t w = 0;
  w = put(Reg::TRI_MODE, "GOURAUD", w, s.gouraud);
  w = put(Reg::TRI_MODE, "TEXTURED", w, s.textured);
  w = put(Reg::TRI_MODE, "Z_TEST", w, s.z_test);
  w = put(Reg::TRI_MODE, "Z_FUNC", w, static_cast<unsigned>(s.z_func));
  w = put(Reg::TRI_MODE, "Z_WRITE", w, s.z_write);
  w = put(Reg::TRI_MODE, "BLEND", w, static_cast<unsigned>(s.blend));
  w = put(Reg::TRI_MODE, "DITHER", w, s.dither);
  w = put(Reg::TRI_MODE, "MASK_R", w, s.mask_r);
  w = put(Reg::TRI_MODE, "MASK_G", w, s.mask_g);
  w = put(Reg::TRI_MODE, "MASK_B", w, s.mask_b);
  w = put(Reg::TRI_MODE, "MASK_A", w, s.mask_a);
  w = put(Reg::TRI_MODE, "TEX_DECAL", w, s.tex_decal);
  w = put(Reg::TRI_MODE, "TEMPORAL", w, s.temporal);
  // The phase means something only to the temporal dither; sent without it, a device lacking
  // CAPS bit 6 would flag ERR_BAD_VALUE for a draw that asked for no temporal dither.
  w = put(Reg::TRI_MODE, "DITHER_PHASE", w, s.temporal ? s.dither_phase & 15 : 0);
  return w;
}

Result<std::uint64_t> tex_fmt_word(const TextureFormat& t) {
  auto log2_of = [](unsigned n, const char* what) -> Result<unsigned> {
    if (!std::has_single_bit(n) || n < (1u << protocol::kMinTextureLog2) || n > (1u << protocol::kMaxTextureLog2))
      return make_error(fmt::format("texture {} {} must be a power of two from 8 to 1024", what, n));
    return static_cast<unsigned>(std::countr_zero(n));
  };
  auto wl = log2_of(t.width, "width");
  if (!wl) return wl.error();
  auto hl = log2_of(t.height, "height");
  if (!hl) return hl.error();
  std::uint64_t w = 0;
  w = put(Reg::TEX_FMT, "WIDTH_LOG2", w, *wl);
  w = put(Reg::TEX_FMT, "HEIGHT_LOG2", w, *hl);
  w = put(Reg::TEX_FMT, "WRAP_S", w, static_cast<unsigned>(t.wrap_s));
  w = put(Reg::TEX_FMT, "WRAP_T", w, static_cast<unsigned>(t.wrap_t));
  w = put(Reg::TEX_FMT, "BILINEAR", w, t.bilinear);
  w = put(Reg::TEX_FMT, "FORMAT", w, static_cast<unsigned>(t.format));
  return w;
}

Result<std::uint64_t> address16_word(std::uint64_t a) {
  if (a % 16 != 0) return make_error(fmt::format("address 0x{:x} is not 16-byte aligned", a));
  if (a >= (std::uint64_t{1} << 32)) return make_error(fmt::format("address 0x{:x} is beyond 4 GiB", a));
  return a;  // ADDR occupies bits [31:4]: the byte address itself
}

Result<std::uint64_t> fb_format_word(unsigned width, unsigned height, protocol::PixelFormat f) {
  if (width < 1 || width > protocol::kMaxFramebufferDim || height < 1 || height > protocol::kMaxFramebufferDim)
    return make_error(fmt::format("framebuffer size {}x{} is outside 1..{}", width, height, protocol::kMaxFramebufferDim));
  std::uint64_t w = 0;
  w = put(Reg::FB_FORMAT, "WIDTH", w, width);
  w = put(Reg::FB_FORMAT, "HEIGHT", w, height);
  w = put(Reg::FB_FORMAT, "FORMAT", w, static_cast<unsigned>(f));
  return w;
}

Result<std::uint64_t> scissor_word(unsigned x0, unsigned y0, unsigned x1, unsigned y1) {
  const unsigned lim = protocol::kMaxFramebufferDim;
  if (x0 > lim || x1 > lim || y0 > lim || y1 > lim)
    return make_error(fmt::format("scissor ({}, {})-({}, {}) has a value above {}", x0, y0, x1, y1, lim));
  std::uint64_t w = 0;
  w = put(Reg::SCISSOR, "X0", w, x0);
  w = put(Reg::SCISSOR, "Y0", w, y0);
  w = put(Reg::SCISSOR, "X1", w, x1);
  w = put(Reg::SCISSOR, "Y1", w, y1);
  return w;
}

Result<void> encode_upload(std::uint32_t address, std::span<const std::uint8_t> bytes, std::vector<protocol::Frame>& out) {
  if (address % 8 != 0) return make_error(fmt::format("upload address 0x{:x} is not 8-byte aligned", address));
  if (std::uint64_t{address} + bytes.size() > (std::uint64_t{1} << 32))
    return make_error(fmt::format("upload of {} bytes at 0x{:x} runs past 4 GiB", bytes.size(), address));
  out.push_back(protocol::write_frame(Reg::MEM_ADDR, address));
  for (std::size_t i = 0; i < bytes.size(); i += 8) {
    std::uint64_t word = 0;
    for (std::size_t k = 0; k < 8; ++k) word = (word << 8) | (i + k < bytes.size() ? bytes[i + k] : 0);
    out.push_back(protocol::write_frame(Reg::MEM_DATA, word));
  }
  return {};
}

}  // namespace gpubridge::geometry
