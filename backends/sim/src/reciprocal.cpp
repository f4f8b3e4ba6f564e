#include "reciprocal.hpp"

namespace gpubridge::sim {

ReciprocalUnit::ReciprocalUnit(unsigned table_bits, unsigned nr_steps)
    : bits_(table_bits), steps_(nr_steps), mask_((std::uint64_t{1} << table_bits) - 1) {
  table_.resize(std::size_t{1} << bits_);
  for (std::uint64_t i = 0; i < table_.size(); ++i) {
    // den = 2^(b+1) + 2i + 1; y = floor((2^(b+34) + den) / (2·den)): 1/midpoint rounded, u0.32.
    const unsigned __int128 den = (static_cast<unsigned __int128>(1) << (bits_ + 1)) + 2 * i + 1;
    const unsigned __int128 y = ((static_cast<unsigned __int128>(1) << (bits_ + 34)) + den) / (2 * den);
    table_[i] = y > 0xFFFFFFFFu ? 0xFFFFFFFFu : static_cast<std::uint32_t>(y);
  }
}

}  // namespace gpubridge::sim
