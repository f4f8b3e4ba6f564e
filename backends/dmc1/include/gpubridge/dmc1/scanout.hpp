#pragma once
// The column sender's palette/light stage: a column-buffer entry {light8, index8} becomes the
// RGB565 word the GPU exports (GPU_EXPORT build): per channel c6' = (c6 * light8) >> 8, then
// r5 = r6' >> 1, g6 = g6', b5 = b6' >> 1. The 65,536 possible entries are precomputed once per
// palette, so scan-out is one table read per pixel.
#include <cstdint>
#include <span>
#include <vector>

#include "gpubridge/dmc1/palette.hpp"

namespace gpubridge::dmc1 {

// The RTL's arithmetic for one entry (the reference the table is built from).
std::uint16_t rgb565_of(const Palette& p, std::uint16_t entry);

class Scanout {
 public:
  explicit Scanout(const Palette& p);
  std::uint16_t pixel(std::uint16_t entry) const { return table_[entry]; }
  // rows[0..n) -> out[0..n)
  void column(const std::uint16_t* __restrict entries, std::uint16_t* __restrict out, unsigned n) const {
    const std::uint16_t* __restrict table = table_.data();
    for (unsigned i = 0; i < n; ++i) out[i] = table[entries[i]];
  }

 private:
  std::vector<std::uint16_t> table_;  // 65,536 words
};

}  // namespace gpubridge::dmc1
