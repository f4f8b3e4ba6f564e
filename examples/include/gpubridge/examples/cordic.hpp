#pragma once
// Shift-and-add rotation (CORDIC, rotation mode), as the donut ASIC of seed 003 rotates without
// multipliers: a 2-D vector in fixed point is turned by a binary angle with `iterations` steps of
// x -= d·(y >> i), y += d·(x >> i), each worth ±atan(2^-i). After n steps the angle is met within
// atan(2^-(n-1)) and the vector is longer by the constant gain K(n) = prod sqrt(1 + 2^-2i), which a
// caller folds into its inputs once (no per-step correction).
#include <cstdint>

namespace gpubridge::examples::cordic {

inline constexpr unsigned kMinIterations = 4, kMaxIterations = 16;
inline constexpr int kFractionBits = 24;  // fixed point: value · 2^24 in an int32 (|value| < 64)

// Binary angle: 2^32 is one turn (wraps like an angle).
using Angle = std::uint32_t;
Angle to_angle(double radians);

struct Vec2 {
  std::int32_t x = 0, y = 0;
};

std::int32_t to_fixed(double v);
double from_fixed(std::int32_t v);

// K(n) = prod_{i<n} sqrt(1 + 2^-2i): the length gain of n steps (about 1.6468 for n >= 8).
double gain(unsigned iterations);

// (x, y) turned counter-clockwise by `angle` and scaled by gain(iterations). Angles beyond ±90°
// are first brought inside by an exact half turn (negating the vector). iterations: 0..16 (more
// are taken as 16).
Vec2 rotate(Vec2 v, Angle angle, unsigned iterations);

}  // namespace gpubridge::examples::cordic
