#pragma once
// The RTL's register widths as C++ helpers: Silice int24/int32 registers wrap, sign extension
// from a field, and the 1/n table (inv_y) every plane and terrain computation reads.
#include <array>
#include <cstdint>

namespace gpubridge::dmc1 {

// Sign-extends the low `bits` bits of v.
constexpr std::int32_t sext(std::uint64_t v, unsigned bits) {
  const std::uint64_t m = 1ull << (bits - 1);
  v &= (m << 1) - 1;
  return static_cast<std::int32_t>(static_cast<std::int64_t>(v ^ m) - static_cast<std::int64_t>(m));
}
// An int24 register after an assignment (two shifts: it sits in every per-row step).
constexpr std::int32_t wrap24(std::int64_t v) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(v) << 8) >> 8;
}
// An int32 register (the multiply-add's result) after an assignment.
constexpr std::int32_t wrap32(std::int64_t v) { return static_cast<std::int32_t>(static_cast<std::uint32_t>(v)); }

// inv_y: 2048 x 16-bit BRAM, entry n = 65536 / n for n >= 2, entries 0 and 1 = 65535.
struct InverseTable {
  std::array<std::uint16_t, 2048> entry{};
  constexpr InverseTable() {
    entry[0] = entry[1] = 65535;
    for (unsigned n = 2; n < 2048; ++n) entry[n] = static_cast<std::uint16_t>(65536 / n);
  }
  // Planes read the entry as signed: 65535, 65535, 32768 (n = 0, 1, 2) become -1, -1, -32768.
  constexpr std::int32_t signed_at(unsigned n) const { return static_cast<std::int16_t>(entry[n & 2047]); }
  constexpr std::uint32_t unsigned_at(unsigned n) const { return entry[n & 2047]; }
};
inline constexpr InverseTable kInverse{};

// The plane path's table index: the integer part of |dot_ray| (24-bit negate), bits above 18 dropped.
constexpr unsigned plane_inverse_index(std::int32_t dot_ray) {
  const std::uint32_t magnitude = dot_ray < 0 ? static_cast<std::uint32_t>(-dot_ray) & 0xFFFFFF : static_cast<std::uint32_t>(dot_ray);
  return (magnitude >> 8) & 2047;
}

// ray_t: t = (1/|dot_ray| * ded) >>> 6, the multiply-add's first pass (int32).
constexpr std::int32_t plane_ray_t(std::int32_t dot_ray, std::int32_t ded) {
  return (kInverse.signed_at(plane_inverse_index(dot_ray)) * ded) >> 6;  // |product| < 2^31: no wrap
}
// A plane texture coordinate register (tr_u / tr_v): ((t * dot) mod 2^32 >>> 10) + offset. Only
// bits below 24 are ever read, so the int24 wrap is left to the caller's mask.
constexpr std::int32_t plane_coordinate(std::int32_t ray_t, std::int32_t dot, std::int32_t offset) {
  // The low 32 bits of the product are the unsigned 32-bit product's.
  const std::uint32_t product = static_cast<std::uint32_t>(ray_t) * static_cast<std::uint32_t>(dot);
  return (static_cast<std::int32_t>(product) >> 10) + offset;
}

// Distance darkening: L4 = max(0, L - min(10, obscure)), obscure = 15 beyond 65,535, else dist >> 12.
constexpr unsigned light_nibble(unsigned light, std::uint32_t dist) {
  const std::uint32_t obscure = dist >> 12 < 10 ? dist >> 12 : 10;
  return light > obscure ? light - obscure : 0;
}

inline constexpr std::uint8_t kBackgroundTexel = 99;  // texture id 0: no fetch, this index, light 15
inline constexpr std::uint8_t kTransparentTexel = 255;

}  // namespace gpubridge::dmc1
