#include "gpubridge/examples/cordic.hpp"

#include <array>
#include <cmath>
#include <numbers>

namespace gpubridge::examples::cordic {
namespace {

// atan(2^-i) as binary angles (the table a gateware would hold in 16 constants).
const std::array<std::int32_t, kMaxIterations>& atan_table() {
  static const auto table = [] {
    std::array<std::int32_t, kMaxIterations> t{};
    for (unsigned i = 0; i < kMaxIterations; ++i)
      t[i] = static_cast<std::int32_t>(std::lround(std::atan(std::ldexp(1.0, -static_cast<int>(i))) / (2 * std::numbers::pi) * 0x1p32));
    return t;
  }();
  return table;
}

}  // namespace

Angle to_angle(double radians) {
  const double turns = radians / (2 * std::numbers::pi);
  const double frac = turns - std::floor(turns);  // [0, 1)
  return static_cast<Angle>(static_cast<std::uint64_t>(std::llround(frac * 0x1p32)) & 0xFFFFFFFFu);
}

std::int32_t to_fixed(double v) { return static_cast<std::int32_t>(std::lround(v * (1 << kFractionBits))); }
double from_fixed(std::int32_t v) { return std::ldexp(static_cast<double>(v), -kFractionBits); }

double gain(unsigned iterations) {
  double k = 1;
  for (unsigned i = 0; i < iterations; ++i) k *= std::sqrt(1 + std::ldexp(1.0, -2 * static_cast<int>(i)));
  return k;
}

Vec2 rotate(Vec2 v, Angle angle, unsigned iterations) {
  // Signed angle in (-1/2, 1/2] turn; outside ±1/4 turn, rotate by a half turn first (exact).
  std::int32_t z = static_cast<std::int32_t>(angle);
  if (z > (1 << 30) || z < -(1 << 30)) {
    v = {-v.x, -v.y};
    z = static_cast<std::int32_t>(angle + 0x80000000u);
  }
  const auto& atans = atan_table();
  if (iterations > kMaxIterations) iterations = kMaxIterations;
  for (unsigned i = 0; i < iterations; ++i) {
    // One step: turn by ±atan(2^-i) toward the remaining angle (arithmetic shifts, no multiply).
    const std::int32_t dx = v.y >> i, dy = v.x >> i;
    if (z >= 0) {
      v.x -= dx;
      v.y += dy;
      z -= atans[i];
    } else {
      v.x += dx;
      v.y -= dy;
      z += atans[i];
    }
  }
  return v;
}

}  // namespace gpubridge::examples::cordic
