#include "gpubridge/dmc1/scanout.hpp"

namespace gpubridge::dmc1 {

std::uint16_t rgb565_of(const Palette& p, std::uint16_t entry) {
  const std::uint32_t light = entry >> 8, rgb = p.entry(entry & 255);
  const std::uint32_t r6 = ((rgb >> 12 & 63) * light) >> 8;
  const std::uint32_t g6 = ((rgb >> 6 & 63) * light) >> 8;
  const std::uint32_t b6 = ((rgb & 63) * light) >> 8;
  return static_cast<std::uint16_t>((r6 >> 1) << 11 | g6 << 5 | (b6 >> 1));
}

Scanout::Scanout(const Palette& p) : table_(65536) {
  for (std::uint32_t e = 0; e < 65536; ++e) table_[e] = rgb565_of(p, static_cast<std::uint16_t>(e));
}

}  // namespace gpubridge::dmc1
