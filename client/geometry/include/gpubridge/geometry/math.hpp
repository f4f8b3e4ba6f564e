#pragma once
// Small vector/matrix types for the host geometry pipeline.
//
// Everything is double precision: the host side has time to spare compared with the SPI link, and
// doubles keep the clipping and normalisation error (≈1e-16 relative) far below the device's
// register resolution (1/16 px, 2^-24 depth, 2^-32 Q), so the documented error bounds are those
// of the register formats alone.
//
// Conventions (same as Direct3D/Vulkan clip space): right-handed view space looking down −z,
// clip-space depth z_clip/w in [0, 1] (0 = near), w = distance in front of the eye for
// perspective(). Matrices are column-vector style: p' = M * p; compose as P * V * M.
#include <array>
#include <cmath>

namespace gpubridge::geometry {

struct Vec2 {
  double x = 0, y = 0;
  friend bool operator==(const Vec2&, const Vec2&) = default;
};
struct Vec3 {
  double x = 0, y = 0, z = 0;
  friend bool operator==(const Vec3&, const Vec3&) = default;
};
struct Vec4 {
  double x = 0, y = 0, z = 0, w = 0;
  friend bool operator==(const Vec4&, const Vec4&) = default;
};

constexpr Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
constexpr Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
constexpr Vec2 operator*(Vec2 a, double s) { return {a.x * s, a.y * s}; }
constexpr Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
constexpr Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
constexpr Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
constexpr Vec3 operator*(Vec3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
constexpr Vec4 operator+(Vec4 a, Vec4 b) { return {a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w}; }
constexpr Vec4 operator-(Vec4 a, Vec4 b) { return {a.x - b.x, a.y - b.y, a.z - b.z, a.w - b.w}; }
constexpr Vec4 operator*(Vec4 a, double s) { return {a.x * s, a.y * s, a.z * s, a.w * s}; }

constexpr double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr double dot(Vec4 a, Vec4 b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }
constexpr Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double length(Vec3 a) { return std::sqrt(dot(a, a)); }
// Returns a unit vector, or the zero vector for a zero/non-finite input (callers check).
Vec3 normalize(Vec3 a);

// Linear interpolation a + (b - a) * t.
constexpr Vec2 lerp(Vec2 a, Vec2 b, double t) { return a + (b - a) * t; }
constexpr Vec4 lerp(Vec4 a, Vec4 b, double t) { return a + (b - a) * t; }

// 4x4 matrix, m[row][col].
struct Mat4 {
  std::array<std::array<double, 4>, 4> m{};
  friend bool operator==(const Mat4&, const Mat4&) = default;
};

Mat4 identity();
Mat4 operator*(const Mat4& a, const Mat4& b);
Vec4 operator*(const Mat4& a, Vec4 v);
inline Vec4 point(Vec3 p) { return {p.x, p.y, p.z, 1.0}; }

Mat4 translate(Vec3 t);
Mat4 scale(Vec3 s);
Mat4 rotate_x(double radians);
Mat4 rotate_y(double radians);
Mat4 rotate_z(double radians);
Mat4 rotate(Vec3 axis, double radians);  // axis need not be unit length
// View matrix: eye at `eye` looking at `target`; `up` roughly up.
Mat4 look_at(Vec3 eye, Vec3 target, Vec3 up);
// Perspective projection, fovy in radians, depth 0 at `near_z`, 1 at `far_z` (both > 0),
// w_clip = -z_view (the distance in front of the eye).
Mat4 perspective(double fovy, double aspect, double near_z, double far_z);
// Orthographic projection: x in [l, r] → [-1, 1], y in [b, t] → [-1, 1], -z_view in [n, f] → [0, 1].
Mat4 orthographic(double l, double r, double b, double t, double n, double f);

// Where normalised device coordinates land on the framebuffer. x right, y DOWN (row 0 at the
// top): ndc (-1, +1) maps to the top-left corner (x, y) of the viewport.
struct Viewport {
  double x = 0, y = 0, width = 640, height = 480;
};
// Maps clip space to window-homogeneous space (X, Y, Z, W) = (sx·w, sy·w, z_ndc·w, w), where
// (sx, sy) are pixel coordinates and z_ndc the depth in [0, 1]. Because this map is linear,
// clipping in window-homogeneous space is exactly clipping in clip space.
Mat4 viewport_matrix(const Viewport& vp);

}  // namespace gpubridge::geometry
