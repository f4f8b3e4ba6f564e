// Transforms: the projection conventions the clipper relies on (depth 0 at near, 1 at far,
// w = distance in front of the eye) and the viewport's y-down mapping.
#include <gtest/gtest.h>

#include <numbers>

#include "gpubridge/geometry/math.hpp"

namespace gpubridge::geometry {
namespace {

TEST(Math, PerspectiveMapsNearToZeroAndFarToOne) {
  const Mat4 p = perspective(std::numbers::pi / 2, 1.0, 0.5, 100.0);
  const Vec4 n = p * Vec4{0, 0, -0.5, 1};
  const Vec4 f = p * Vec4{0, 0, -100, 1};
  EXPECT_NEAR(n.z / n.w, 0.0, 1e-12);
  EXPECT_NEAR(f.z / f.w, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(n.w, 0.5);  // w is the distance in front of the eye
  EXPECT_DOUBLE_EQ(f.w, 100.0);
  // 90° field of view: a point at 45° up lands on the top edge (ndc y = 1).
  const Vec4 top = p * Vec4{0, 3, -3, 1};
  EXPECT_NEAR(top.y / top.w, 1.0, 1e-12);
}

TEST(Math, ViewportMapsNdcCornersYDown) {
  const Mat4 v = viewport_matrix(Viewport{10, 20, 640, 480});
  const Vec4 tl = v * Vec4{-1, 1, 0.25, 1};
  EXPECT_DOUBLE_EQ(tl.x, 10);
  EXPECT_DOUBLE_EQ(tl.y, 20);
  EXPECT_DOUBLE_EQ(tl.z, 0.25);
  const Vec4 br = v * Vec4{2, -2, 1, 2};  // ndc (1, -1) with w = 2: window-homogeneous = pixel · w
  EXPECT_DOUBLE_EQ(br.x / br.w, 650);
  EXPECT_DOUBLE_EQ(br.y / br.w, 500);
}

TEST(Math, LookAtPutsTargetOnNegativeZ) {
  const Mat4 v = look_at({1, 2, 3}, {1, 2, -7}, {0, 1, 0});
  const Vec4 t = v * Vec4{1, 2, -7, 1};
  EXPECT_NEAR(t.x, 0, 1e-12);
  EXPECT_NEAR(t.y, 0, 1e-12);
  EXPECT_NEAR(t.z, -10, 1e-12);
}

TEST(Math, RotationIsOrthonormal) {
  const Mat4 r = rotate({1, 2, 3}, 0.7);
  const Vec4 a = r * Vec4{1, 0, 0, 0}, b = r * Vec4{0, 1, 0, 0};
  EXPECT_NEAR(dot(a, a), 1, 1e-12);
  EXPECT_NEAR(dot(a, b), 0, 1e-12);
  const Vec4 z = rotate_z(std::numbers::pi / 2) * Vec4{1, 0, 0, 1};
  EXPECT_NEAR(z.x, 0, 1e-12);
  EXPECT_NEAR(z.y, 1, 1e-12);
}

TEST(Math, MatrixProductComposesRightToLeft) {
  const Mat4 m = translate({5, 0, 0}) * scale({2, 2, 2});
  const Vec4 p = m * Vec4{1, 1, 1, 1};
  EXPECT_EQ(p, (Vec4{7, 2, 2, 1}));
}

}  // namespace
}  // namespace gpubridge::geometry
