#pragma once
// A private copy of a bound texture laid out for the bilinear filter: "row pairs". Entry (i, j)
// is one 64-bit word holding texel (i, j) in its low half and texel (i, (j + 1) mod height) in its
// high half, both as colour words (byte c = channel c, whatever the texture's format). A bilinear
// footprint whose rows are j and j + 1 is then two 8-byte loads from one row of entries, usually
// in one cache line, where the linear texture needs two rows of texels (two lines, and at the
// cubes' minification no two samples share one): docs/simulator.md, "Issue 17 Part 2: a row-pair
// shadow of the texture". Video memory stays linear: the device's view never changes; a shadow
// is only read by the texture unit (TextureUnit::quad) and is dropped whenever any byte under its
// texture is written.
//
// Threads: only the device thread changes the shadows (build, invalidate), and only while the
// renderer is idle (it flushes first); band workers only read them (find). Device::write paths
// that write video memory flush the renderer before writing, and a queued draw whose colour or
// depth buffer overlaps a shadowed texture flushes and drops it (kick, device.cpp).
#include <array>
#include <cstdint>
#include <cstdlib>
#include <memory>

#include "draw_state.hpp"

namespace gpubridge::sim {

class TextureShadows {
 public:
  // Slots: textures kept at once (a scene alternating between a few textures rebuilds none).
  static constexpr unsigned kSlots = 4;
  // Largest texture shadowed, in texels (2^22: 32 MiB of entries); larger ones stay linear.
  static constexpr unsigned kMaxLog2Texels = 22;

  // The entries of `tex` when a valid shadow of it exists, else nullptr. Band workers call this.
  const std::uint64_t* find(const TextureState& tex) const {
    if (valid_ == 0) return nullptr;
    for (unsigned k = 0; k < kSlots; ++k)
      if ((valid_ >> k & 1) && slots_[k].matches(tex)) return slots_[k].entries.get();
    return nullptr;
  }

  // Device thread, before a triangle of `st` is queued: true when the shadows must change first
  // (a shadow to build for st's texture, or one under a buffer st writes to drop). The caller
  // then flushes the renderer and calls update(). Two compares for untextured draws with no shadow.
  // `preview`: the device runs `--accuracy preview`.
  bool outdated(const DrawState& st, bool preview) const {
    if (valid_ == 0 && !st.textured) return false;
    if (valid_ != 0 && overlaps_written(st)) return true;
    return wanted(st, preview) && find(st.tex) == nullptr;
  }
  // Drops the shadows under st's written buffers and builds st's texture's from `vram` (the
  // renderer idle).
  void update(const DrawState& st, const std::uint8_t* vram, bool preview);

  // Drops every shadow whose texture overlaps [address, address + length) (a write there).
  void invalidate(std::uint64_t address, std::uint64_t length) {
    if (valid_ == 0) return;
    for (unsigned k = 0; k < kSlots; ++k)
      if ((valid_ >> k & 1) && slots_[k].overlaps(address, length)) valid_ &= ~(1u << k);
  }
  void invalidate_all() { valid_ = 0; }

  // Whether draws of `st` use a shadow of their texture: bilinear, wholly inside video memory,
  // not too large, not under a buffer the same draw writes, and not drawn by the preview's plain
  // kernel (which reads the linear texture).
  static bool wanted(const DrawState& st, bool preview);

 private:
  struct Free {
    void operator()(std::uint64_t* p) const { std::free(p); }
  };
  struct Slot {
    std::uint32_t base = 0;
    unsigned wl = 0, hl = 0;
    protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
    std::uint64_t bytes = 0;     // the texture's size in video memory
    std::uint64_t capacity = 0;  // entries allocated
    std::uint64_t last_use = 0;
    std::unique_ptr<std::uint64_t[], Free> entries;
    bool matches(const TextureState& t) const {
      return t.base == base && t.wl == wl && t.hl == hl && t.format == format;
    }
    bool overlaps(std::uint64_t address, std::uint64_t length) const {
      return address < std::uint64_t{base} + bytes && base < address + length;
    }
  };
  // A valid shadow lies under a buffer `st` writes (colour; depth when it writes Z).
  bool overlaps_written(const DrawState& st) const;

  std::array<Slot, kSlots> slots_{};
  unsigned valid_ = 0;  // bit k: slot k holds a current shadow
  std::uint64_t uses_ = 0;
};

}  // namespace gpubridge::sim
