#pragma once
// Exact integer helpers shared by the stages: floor division, 128-bit intermediates, big-endian
// memory words. Everything here is exact; no floating point.
#include <bit>
#include <cstdint>
#include <cstring>

namespace gpubridge::sim {

using i128 = __int128;

// floor(a / b) and the matching non-negative remainder, for b > 0.
struct DivMod {
  std::int64_t q, r;
};
inline DivMod floor_divmod(std::int64_t a, std::int64_t b) {
  std::int64_t q = a / b, r = a % b;
  if (r < 0) { r += b; --q; }
  return {q, r};
}
inline DivMod floor_divmod128(i128 a, std::int64_t b) {
  // Fast path: most values fit in 64 bits (colours, Z, small triangles).
  if (a >= INT64_MIN && a <= INT64_MAX) return floor_divmod(static_cast<std::int64_t>(a), b);
  i128 q = a / b, r = a % b;
  if (r < 0) { r += b; --q; }
  return {static_cast<std::int64_t>(q), static_cast<std::int64_t>(r)};
}
// Floor division by a fixed positive divisor without a hardware divide: a double estimate of the
// quotient (exact to within one for |a| < 2^52) corrected with integer arithmetic, so the result
// is exactly floor_divmod's. Larger numerators use the integer divide.
class Divider {
 public:
  explicit Divider(std::int64_t d) : d_(d), inv_(1.0 / static_cast<double>(d)) {}
  // Always inlined: it sits in the rasteriser's per-row loops (a call there costs measurably).
  [[gnu::always_inline]] DivMod operator()(std::int64_t a) const {
    constexpr std::int64_t kExact = std::int64_t{1} << 52;
    if (a >= kExact || a <= -kExact) return floor_divmod(a, d_);
    std::int64_t q = static_cast<std::int64_t>(static_cast<double>(a) * inv_);
    std::int64_t r = a - q * d_;
    // Branches, not selects: in the rasteriser's per-row span solving the numerator's sign (and
    // so the correction) repeats row after row and predicts well; selects cost more there.
    while (r < 0) { r += d_; --q; }
    while (r >= d_) { r -= d_; ++q; }
    return {q, r};
  }
  DivMod operator()(i128 a) const {
    if (a >= INT64_MIN && a <= INT64_MAX) return (*this)(static_cast<std::int64_t>(a));
    return floor_divmod128(a, d_);
  }
  std::int64_t divisor() const { return d_; }

 private:
  std::int64_t d_;
  double inv_;
};

inline std::int64_t floor_div(std::int64_t a, std::int64_t b) { return floor_divmod(a, b).q; }
inline std::int64_t ceil_div(std::int64_t a, std::int64_t b) { return -floor_div(-a, b); }

inline std::uint32_t load_be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}
inline void store_be32(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}
// One load/store and a byte swap (the compiler does not merge the byte-wise form here); the
// frame front end decodes and re-encodes one of these per register write.
inline std::uint64_t load_be64(const std::uint8_t* p) {
  std::uint64_t v;
  std::memcpy(&v, p, 8);
  return std::endian::native == std::endian::little ? __builtin_bswap64(v) : v;
}
inline void store_be64(std::uint8_t* p, std::uint64_t v) {
  if constexpr (std::endian::native == std::endian::little) v = __builtin_bswap64(v);
  std::memcpy(p, &v, 8);
}

// div255 of docs/protocol.md section 10.5: round(x / 255) for 0 <= x <= 65025.
constexpr unsigned div255(unsigned x) { return (x + 128 + ((x + 128) >> 8)) >> 8; }

}  // namespace gpubridge::sim
