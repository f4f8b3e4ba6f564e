#include "hier_z.hpp"

#include <cstring>

namespace gpubridge::sim {

// Eight words at a time in the AVX2 clone (a block row of 32 pixels is four vectors).
__attribute__((target_clones("avx2", "default"))) std::uint32_t depth_block_max(const std::uint8_t* z, std::size_t pitch,
                                                                                unsigned rows, unsigned cols) {
  std::uint32_t m = 0;
  for (unsigned r = 0; r < rows; ++r, z += pitch) {
    for (unsigned c = 0; c < cols; ++c) {
      std::uint32_t w;
      std::memcpy(&w, z + std::size_t{c} * 4, 4);
      w = __builtin_bswap32(w) & 0xFFFFFFu;  // stored big-endian
      m = w > m ? w : m;
    }
  }
  return m;
}

}  // namespace gpubridge::sim
