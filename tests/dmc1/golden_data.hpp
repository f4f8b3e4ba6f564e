#pragma once
// The RTL goldens of tests/dmc1/data (README.md there): streams, texture image, palette, the
// expected RGB565 output and cycle counts, loaded once per test binary.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gpubridge/dmc1/palette.hpp"
#include "gpubridge/dmc1/stream.hpp"
#include "gpubridge/dmc1/texture_memory.hpp"

namespace gpubridge::dmc1::test {

inline const std::filesystem::path kDataDir = GPUBRIDGE_DMC1_DATA_DIR;
inline const char* const kGoldenStreams[] = {"walls", "planes", "mixed", "terrain", "edge"};

inline std::vector<std::uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), {}};
}

inline std::shared_ptr<const TextureMemory> golden_textures() {
  static const std::shared_ptr<const TextureMemory> mem = [] {
    auto m = load_texture_memory(kDataDir / "textures.bin.gz");
    if (!m) throw std::runtime_error(m.error().message);
    return *m;
  }();
  return mem;
}

inline const Palette& golden_palette() {
  static const Palette p = [] {
    auto r = load_palette(kDataDir / "palette.bin");
    if (!r) throw std::runtime_error(r.error().message);
    return *r;
  }();
  return p;
}

inline std::vector<std::uint64_t> golden_stream(const std::string& name) {
  auto s = load_stream(kDataDir / "streams" / (name + ".dmc1"));
  if (!s) throw std::runtime_error(s.error().message);
  return s->words;
}

// golden/NAME.rgb565: little-endian words, frames back to back.
inline std::vector<std::uint16_t> golden_pixels(const std::string& name) {
  const auto bytes = read_bytes(kDataDir / "golden" / (name + ".rgb565"));
  std::vector<std::uint16_t> words(bytes.size() / 2);
  for (std::size_t i = 0; i < words.size(); ++i) words[i] = static_cast<std::uint16_t>(bytes[2 * i] | bytes[2 * i + 1] << 8);
  return words;
}

inline std::vector<std::uint64_t> golden_cycles(const std::string& name) {
  std::ifstream f(kDataDir / "golden" / (name + ".cycles"));
  std::vector<std::uint64_t> v;
  for (std::uint64_t c; f >> c;) v.push_back(c);
  return v;
}

}  // namespace gpubridge::dmc1::test
