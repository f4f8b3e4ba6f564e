// The torus example's two ideas from the donut ASIC (issue 23). Shift-and-add (CORDIC) rotation:
// the rotation meets the angle within the CORDIC bound after n steps, and the torus's CORDIC
// vertices converge to the floating-point ones as the iteration count grows. Temporal dither: the
// figures' frame means approach the 8-bit reference.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <random>

#include "gpubridge/examples/cordic.hpp"
#include "gpubridge/examples/figures.hpp"
#include "gpubridge/examples/torus.hpp"

namespace gpubridge::examples {
namespace {

// Bound: after n steps the remaining angle is at most atan(2^-(n-1)) (the last step's size), so
// the scaled result lies within K(n)·|v|·atan(2^-(n-1)) of K(n)·(exact rotation), plus a few LSB of
// shift truncation per step. Checked on random vectors and angles over the whole circle.
TEST(Cordic, RotationWithinTheAngleBound) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> coord(-1.5, 1.5), angle(-2 * std::numbers::pi, 2 * std::numbers::pi);
  for (unsigned n = cordic::kMinIterations; n <= cordic::kMaxIterations; ++n) {
    const double k = cordic::gain(n), residual = std::atan(std::ldexp(1.0, 1 - int(n)));
    double worst = 0;
    for (int i = 0; i < 2000; ++i) {
      const double x = coord(rng), y = coord(rng), a = angle(rng);
      const auto r = cordic::rotate({cordic::to_fixed(x), cordic::to_fixed(y)}, cordic::to_angle(a), n);
      const double ex = k * (x * std::cos(a) - y * std::sin(a)), ey = k * (x * std::sin(a) + y * std::cos(a));
      const double err = std::hypot(cordic::from_fixed(r.x) - ex, cordic::from_fixed(r.y) - ey);
      const double bound = k * std::hypot(x, y) * residual + 2.0 * n * std::ldexp(1.0, -cordic::kFractionBits);
      ASSERT_LE(err, bound) << n << " iterations, v = (" << x << ", " << y << "), angle " << a;
      worst = std::max(worst, err / (k * std::hypot(x, y)));
    }
    // The bound is not loose by more than a factor of 4 (the worst angle is met on a random set).
    EXPECT_GT(worst, residual / 4) << n;
  }
  EXPECT_NEAR(cordic::gain(16), 1.6467602581, 1e-9);
}

TEST(Cordic, QuarterTurnsAreExactUpToTheGain) {
  const auto v = cordic::rotate({cordic::to_fixed(1.0), 0}, cordic::to_angle(std::numbers::pi), 16);
  EXPECT_NEAR(cordic::from_fixed(v.x), -cordic::gain(16), 1e-4);
  EXPECT_NEAR(cordic::from_fixed(v.y), 0, 1e-4);
}

// The CORDIC vertex stage of the torus: world positions and colours approach the floating-point
// path's (model · position, same shading) as iterations grow; at 16 they agree within 1e-4.
TEST(TorusCordic, ConvergesToTheFloatingPointVertices) {
  const TorusGeometry ref(0);
  double previous = 1e9;
  for (unsigned n : {4u, 8u, 12u, 16u}) {
    const TorusGeometry geo(n);
    double worst_pos = 0, worst_color = 0;
    for (unsigned frame : {0u, 7u, 40u}) {
      TorusGeometry::Frame a, b;
      ref.frame(frame, a);
      geo.frame(frame, b);
      ASSERT_EQ(a.vertices.size(), b.vertices.size());
      for (std::size_t i = 0; i < a.vertices.size(); ++i) {
        const auto p = a.model * geometry::Vec4{a.vertices[i].position.x, a.vertices[i].position.y, a.vertices[i].position.z, 1};
        const auto q = b.model * geometry::Vec4{b.vertices[i].position.x, b.vertices[i].position.y, b.vertices[i].position.z, 1};
        worst_pos = std::max(worst_pos, std::hypot(p.x - q.x, p.y - q.y, p.z - q.z));
        const auto ca = a.vertices[i].color, cb = b.vertices[i].color;
        worst_color = std::max({worst_color, std::abs(ca.x - cb.x), std::abs(ca.y - cb.y), std::abs(ca.z - cb.z)});
      }
    }
    EXPECT_LT(worst_pos, previous) << n << " iterations";
    previous = worst_pos;
    if (n == 16) {
      EXPECT_LT(worst_pos, 1e-4);
      EXPECT_LT(worst_color, 1e-3);
    }
    if (n == 4) {
      EXPECT_GT(worst_pos, 1e-2) << "4 iterations should visibly move vertices";
    }
  }
}

// The figures of docs/examples.md: every file is written, and the temporal dither's frame means
// approach the 8-bit reference (error shrinking with every doubling of frames, about one LSB after
// 16), while the ordered dither stays far off (its quantiser's 85·v/64 levels).
TEST(ExampleFigures, TemporalMeansApproachTheReference) {
  const auto dir = std::filesystem::path(GPUBRIDGE_GOLDEN_OUT) / "figures";
  std::filesystem::remove_all(dir);
  auto figures = write_figures(dir);
  ASSERT_TRUE(figures) << figures.error().message;
  std::map<std::string, double> error;
  for (const auto& f : *figures) {
    EXPECT_TRUE(std::filesystem::exists(dir / f.file)) << f.file;
    if (f.has_error) error[f.file] = f.mean_error;
  }
  ASSERT_EQ(error.size(), 6u);
  const double ordered = error["dither-ordered.png"], one = error["dither-temporal.png"];
  double previous = one;
  for (int n : {2, 4, 8, 16}) {
    const double e = error["dither-temporal-mean" + std::to_string(n) + ".png"];
    EXPECT_LT(e, previous * 0.6) << n << " frames";
    previous = e;
  }
  EXPECT_LT(previous, 2.0);
  EXPECT_GT(ordered, 10 * previous);
}

}  // namespace
}  // namespace gpubridge::examples
