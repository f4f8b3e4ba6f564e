#include "texture_shadow.hpp"

#include <cstring>
#include <new>

#include <sys/mman.h>

#include "gpubridge/protocol/pixel.hpp"

namespace gpubridge::sim {
namespace {

std::uint64_t texture_bytes(const TextureState& t) {
  return (std::uint64_t{1} << (t.wl + t.hl)) * protocol::bytes_per_pixel(t.format);
}

bool apart(std::uint64_t a, std::uint64_t alen, std::uint64_t b, std::uint64_t blen) {
  return a + alen <= b || b + blen <= a;
}

// The buffers a draw of `st` may write: [colour), [depth) (length 0 when it writes no Z).
struct Written {
  std::uint64_t color, color_len, depth, depth_len;
};
Written written(const DrawState& st) {
  const std::uint64_t pixels = std::uint64_t{st.fb_width} * st.fb_height;
  return {st.fb_draw, pixels * st.bpp, st.fb_z, st.z_write ? pixels * 4 : 0};
}

std::uint32_t color_word(protocol::Rgba8 c) {
  return std::uint32_t{c.r} | (std::uint32_t{c.g} << 8) | (std::uint32_t{c.b} << 16) | (std::uint32_t{c.a} << 24);
}

}  // namespace

bool TextureShadows::wanted(const DrawState& st, bool preview) {
  if (!st.textured || !st.tex.bilinear || !st.tex.in_vram || st.tex.wl + st.tex.hl > kMaxLog2Texels) return false;
  if (preview && st.preview_plain) return false;
  const Written w = written(st);
  const std::uint64_t tlen = texture_bytes(st.tex);
  return apart(st.tex.base, tlen, w.color, w.color_len) && apart(st.tex.base, tlen, w.depth, w.depth_len);
}

bool TextureShadows::overlaps_written(const DrawState& st) const {
  const Written w = written(st);
  for (unsigned k = 0; k < kSlots; ++k) {
    if (!(valid_ >> k & 1)) continue;
    if (slots_[k].overlaps(w.color, w.color_len) || slots_[k].overlaps(w.depth, w.depth_len)) return true;
  }
  return false;
}

void TextureShadows::update(const DrawState& st, const std::uint8_t* vram, bool preview) {
  const Written w = written(st);
  invalidate(w.color, w.color_len);
  invalidate(w.depth, w.depth_len);
  if (!wanted(st, preview) || find(st.tex) != nullptr) return;
  // The slot: one already holding this texture's (stale) entries, else a free one, else the
  // least recently built.
  unsigned pick = kSlots;
  for (unsigned k = 0; k < kSlots && pick == kSlots; ++k)
    if (slots_[k].matches(st.tex) && slots_[k].entries) pick = k;
  for (unsigned k = 0; k < kSlots && pick == kSlots; ++k)
    if (!(valid_ >> k & 1)) pick = k;
  if (pick == kSlots) {
    pick = 0;
    for (unsigned k = 1; k < kSlots; ++k)
      if (slots_[k].last_use < slots_[pick].last_use) pick = k;
  }
  Slot& s = slots_[pick];
  const unsigned wl = st.tex.wl, hl = st.tex.hl;
  const std::uint64_t count = std::uint64_t{1} << (wl + hl);
  if (s.capacity < count) {
    // 2 MiB pages for large shadows, as VideoMemory's (a row of entries is 8 KiB at 1,024 texels).
    constexpr std::size_t kHugePage = std::size_t{2} << 20;
    const std::size_t bytes = static_cast<std::size_t>(count * 8);
    const bool huge = bytes >= kHugePage;
    const std::size_t align = huge ? kHugePage : 64;
    const std::size_t rounded = (bytes + align - 1) & ~(align - 1);
    auto* p = static_cast<std::uint64_t*>(std::aligned_alloc(align, rounded));
    if (!p) throw std::bad_alloc();
    if (huge) (void)madvise(p, rounded, MADV_HUGEPAGE);  // a hint, as VideoMemory's
    s.entries.reset(p);
    s.capacity = count;
  }
  s.base = st.tex.base;
  s.wl = wl;
  s.hl = hl;
  s.format = st.tex.format;
  s.bytes = texture_bytes(st.tex);
  s.last_use = ++uses_;
  const std::uint8_t* src = vram + st.tex.base;
  const std::uint64_t width = std::uint64_t{1} << wl, height = std::uint64_t{1} << hl;
  const unsigned bpp = protocol::bytes_per_pixel(st.tex.format);
  std::uint64_t* out = s.entries.get();
  for (std::uint64_t j = 0; j < height; ++j) {
    const std::uint8_t* row0 = src + j * width * bpp;
    const std::uint8_t* row1 = src + ((j + 1) & (height - 1)) * width * bpp;
    std::uint64_t* dst = out + j * width;
    if (st.tex.format == protocol::PixelFormat::RGBA8888) {  // memory order R, G, B, A is the word's byte order
      for (std::uint64_t i = 0; i < width; ++i) {
        std::uint32_t lo, hi;
        std::memcpy(&lo, row0 + i * 4, 4);
        std::memcpy(&hi, row1 + i * 4, 4);
        dst[i] = std::uint64_t{lo} | (std::uint64_t{hi} << 32);
      }
    } else {
      for (std::uint64_t i = 0; i < width; ++i)
        dst[i] = std::uint64_t{color_word(protocol::load_pixel(st.tex.format, row0 + i * bpp))} |
                 (std::uint64_t{color_word(protocol::load_pixel(st.tex.format, row1 + i * bpp))} << 32);
    }
  }
  valid_ |= 1u << pick;
}

}  // namespace gpubridge::sim
