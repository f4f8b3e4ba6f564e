#pragma once
// The DMC-1's texture memory: the 24-bit flash (icebreaker) or PSRAM (MCH2022) address space the
// texture sampler reads a byte at a time. The texture pack (docs/dmc1.md, "Texture image") sits at
// 0x200000: an 8-byte header per texture id, then 8-bit palette-index texels. Addresses outside the
// image read 0. Read-only once loaded, so one image can be shared by devices and threads.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <vector>

#include "gpubridge/common/result.hpp"

namespace gpubridge::dmc1 {

// What binding a texture id latches from its header (bytes 0-3 of its record).
struct TextureBinding {
  std::uint32_t base = 0;  // absolute 24-bit address of texel (0, 0)
  std::uint8_t wp2 = 0;    // log2 width (u is masked with (1 << wp2) - 1)
  std::uint8_t hp2 = 0;    // log2 height
};

class TextureMemory {
 public:
  static constexpr std::uint32_t kAddressBits = 24;
  static constexpr std::uint32_t kSize = 1u << kAddressBits;
  static constexpr std::uint32_t kImageBase = 0x200000;                // byte 0 of the image
  static constexpr std::uint32_t kMaxImageBytes = kSize - kImageBase;  // 14 MiB
  static constexpr std::uint32_t kAddressMask = kSize - 1;

  // All-zero memory (every texture reads as texel 0 at address 0).
  TextureMemory();
  // Errors when the image does not fit below 16 MiB.
  static Result<std::shared_ptr<const TextureMemory>> from_image(std::span<const std::uint8_t> image);

  std::uint8_t read(std::uint32_t address) const { return bytes_[address & kAddressMask]; }
  // The 16 MiB address space, so that hot loops index it directly with a masked address.
  const std::uint8_t* data() const { return bytes_.get(); }
  std::size_t image_bytes() const { return image_bytes_; }

  // Header of texture id `tid` (0..1023): 24-bit little-endian address and (hp2 << 4) | wp2.
  TextureBinding binding(unsigned tid) const;
  // texel(u, v) of a binding, as the sampler addresses it: u and v masked to the texture's size,
  // address = base + (u | v << wp2) in 24-bit arithmetic.
  std::uint8_t texel(const TextureBinding& b, std::uint32_t u, std::uint32_t v) const {
    u &= (1u << b.wp2) - 1;
    v &= (1u << b.hp2) - 1;
    return read(b.base + (u | (v << b.wp2)));
  }

 private:
  struct Free {
    void operator()(std::uint8_t* p) const;
  };
  // 2 MiB-aligned and backed by huge pages where the kernel allows: texel reads land anywhere in
  // the image, and 4 KiB pages would make most of them TLB misses.
  std::unique_ptr<std::uint8_t[], Free> bytes_;
  std::size_t image_bytes_ = 0;
};

// Reads a texture image file: raw bytes, or gzip-compressed (detected by its magic) as the
// repository stores its test image. Errors name the file and what to do.
Result<std::vector<std::uint8_t>> read_texture_image(const std::filesystem::path& path);
Result<std::shared_ptr<const TextureMemory>> load_texture_memory(const std::filesystem::path& path);

}  // namespace gpubridge::dmc1
