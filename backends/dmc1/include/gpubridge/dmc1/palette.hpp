#pragma once
// The DMC-1 palette: 256 entries of 18 bits {R6, G6, B6}, synthesised into the bitstream (the
// build's palette666.si). File form (docs/dmc1.md): 768 bytes, entry i at 3*i as R6, G6, B6, each
// 0..63.
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "gpubridge/common/result.hpp"

namespace gpubridge::dmc1 {

class Palette {
 public:
  static constexpr std::size_t kFileBytes = 768;

  Palette() = default;  // all black
  // Errors name the byte offset of a channel above 63 (what_for_errors prefixes the message).
  static Result<Palette> from_bytes(std::span<const std::uint8_t> bytes, const std::string& what_for_errors);

  // 18-bit {R6[17:12], G6[11:6], B6[5:0]}.
  std::uint32_t entry(unsigned index) const { return entries_[index & 255]; }
  void set(unsigned index, std::uint8_t r6, std::uint8_t g6, std::uint8_t b6);
  std::array<std::uint8_t, kFileBytes> to_bytes() const;
  friend bool operator==(const Palette&, const Palette&) = default;

 private:
  std::array<std::uint32_t, 256> entries_{};
};

Result<Palette> load_palette(const std::filesystem::path& path);

}  // namespace gpubridge::dmc1
