#include "gpubridge/dmc1/palette.hpp"

#include "gpubridge/common/regular_file.hpp"

namespace gpubridge::dmc1 {

Result<Palette> Palette::from_bytes(std::span<const std::uint8_t> bytes, const std::string& what_for_errors) {
  if (bytes.size() != kFileBytes)
    return make_error(what_for_errors + ": a DMC-1 palette is exactly 768 bytes (256 entries of R6, G6, B6), this has " +
                      std::to_string(bytes.size()));
  Palette p;
  for (unsigned i = 0; i < 256; ++i) {
    for (unsigned c = 0; c < 3; ++c)
      if (bytes[3 * i + c] > 63)
        return make_error(what_for_errors + ": byte " + std::to_string(3 * i + c) + " (entry " + std::to_string(i) +
                          ", " + "RGB"[c] + " channel) is " + std::to_string(bytes[3 * i + c]) +
                          "; channels are 6-bit (0..63): convert an 8-bit palette with value >> 2");
    p.set(i, bytes[3 * i], bytes[3 * i + 1], bytes[3 * i + 2]);
  }
  return p;
}

void Palette::set(unsigned index, std::uint8_t r6, std::uint8_t g6, std::uint8_t b6) {
  entries_[index & 255] = (std::uint32_t{r6} & 63) << 12 | (std::uint32_t{g6} & 63) << 6 | (std::uint32_t{b6} & 63);
}

std::array<std::uint8_t, Palette::kFileBytes> Palette::to_bytes() const {
  std::array<std::uint8_t, kFileBytes> b{};
  for (unsigned i = 0; i < 256; ++i) {
    b[3 * i] = static_cast<std::uint8_t>(entries_[i] >> 12 & 63);
    b[3 * i + 1] = static_cast<std::uint8_t>(entries_[i] >> 6 & 63);
    b[3 * i + 2] = static_cast<std::uint8_t>(entries_[i] & 63);
  }
  return b;
}

Result<Palette> load_palette(const std::filesystem::path& path) {
  auto data = read_regular_file(path, Palette::kFileBytes, "palette");
  if (!data) return make_error(data.error().message + " (a DMC-1 palette is 768 bytes: R6, G6, B6 per entry)");
  return Palette::from_bytes({reinterpret_cast<const std::uint8_t*>(data->data()), data->size()}, path.string());
}

}  // namespace gpubridge::dmc1
