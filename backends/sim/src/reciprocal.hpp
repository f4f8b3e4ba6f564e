#pragma once
// The reciprocal unit of docs/protocol.md section 10.1: normalise q, look up a table of
// 1/(interval midpoint), refine with Newton-Raphson. Table bits and step count are accuracy knobs
// (hardware: b = 10, k = 1).
#include <bit>
#include <cstdint>
#include <vector>

namespace gpubridge::sim {

struct Reciprocal {
  std::uint32_t y = 0;  // u0.32 approximation of 1/M, M = m / 2^31 in [1, 2)
  unsigned n = 0;       // leading zeros of q
};

class ReciprocalUnit {
 public:
  ReciprocalUnit(unsigned table_bits, unsigned nr_steps);
  // q must be non-zero.
  [[gnu::always_inline]] Reciprocal operator()(std::uint32_t q) const {
    const unsigned n = static_cast<unsigned>(std::countl_zero(q));
    const std::uint64_t m = std::uint64_t{q} << n;  // 2^31 <= m < 2^32
    std::uint64_t y = table_[(m >> (31 - bits_)) & mask_];
    for (unsigned k = 0; k < steps_; ++k) {
      const std::uint64_t p = m * y;               // < 2^64 (u1.63)
      const std::uint64_t t = (0 - p) >> 32;       // (2^64 − p) mod 2^64, as u1.31
      // y <= 2^32 − 1 (the table's words and the clamp below) and t < 2^32, so y·t < 2^64: one
      // 64-bit multiply, where a 128-bit one cost a widening multiply and a double shift a pixel.
      const std::uint64_t yt = (y * t) >> 31;
      y = yt > 0xFFFFFFFFu ? 0xFFFFFFFFu : yt;
    }
    return {static_cast<std::uint32_t>(y), n};
  }
  unsigned table_bits() const { return bits_; }
  // For the lanes' copy of operator() (texture8_wide.hpp).
  unsigned nr_steps() const { return steps_; }
  const std::uint32_t* table() const { return table_.data(); }

 private:
  unsigned bits_, steps_;
  std::uint64_t mask_;
  std::vector<std::uint32_t> table_;
};

}  // namespace gpubridge::sim
