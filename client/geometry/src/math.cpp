#include "gpubridge/geometry/math.hpp"

namespace gpubridge::geometry {

Vec3 normalize(Vec3 a) {
  const double len = length(a);
  if (!(len > 0) || !std::isfinite(len)) return {};
  return a * (1.0 / len);
}

Mat4 identity() {
  Mat4 r;
  for (int i = 0; i < 4; ++i) r.m[i][i] = 1.0;
  return r;
}

Mat4 operator*(const Mat4& a, const Mat4& b) {
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a.m[i][k] * b.m[k][j];
      r.m[i][j] = s;
    }
  return r;
}

Vec4 operator*(const Mat4& a, Vec4 v) {
  const double in[4] = {v.x, v.y, v.z, v.w};
  double out[4];
  for (int i = 0; i < 4; ++i) out[i] = a.m[i][0] * in[0] + a.m[i][1] * in[1] + a.m[i][2] * in[2] + a.m[i][3] * in[3];
  return {out[0], out[1], out[2], out[3]};
}

Mat4 translate(Vec3 t) {
  Mat4 r = identity();
  r.m[0][3] = t.x;
  r.m[1][3] = t.y;
  r.m[2][3] = t.z;
  return r;
}

Mat4 scale(Vec3 s) {
  Mat4 r;
  r.m[0][0] = s.x;
  r.m[1][1] = s.y;
  r.m[2][2] = s.z;
  r.m[3][3] = 1;
  return r;
}

Mat4 rotate_x(double a) { return rotate({1, 0, 0}, a); }
Mat4 rotate_y(double a) { return rotate({0, 1, 0}, a); }
Mat4 rotate_z(double a) { return rotate({0, 0, 1}, a); }

Mat4 rotate(Vec3 axis, double a) {
  const Vec3 n = normalize(axis);
  const double c = std::cos(a), s = std::sin(a), t = 1 - c;
  Mat4 r = identity();
  r.m[0][0] = t * n.x * n.x + c;
  r.m[0][1] = t * n.x * n.y - s * n.z;
  r.m[0][2] = t * n.x * n.z + s * n.y;
  r.m[1][0] = t * n.x * n.y + s * n.z;
  r.m[1][1] = t * n.y * n.y + c;
  r.m[1][2] = t * n.y * n.z - s * n.x;
  r.m[2][0] = t * n.x * n.z - s * n.y;
  r.m[2][1] = t * n.y * n.z + s * n.x;
  r.m[2][2] = t * n.z * n.z + c;
  return r;
}

Mat4 look_at(Vec3 eye, Vec3 target, Vec3 up) {
  const Vec3 f = normalize(target - eye);
  const Vec3 s = normalize(cross(f, up));
  const Vec3 u = cross(s, f);
  Mat4 r = identity();
  r.m[0][0] = s.x; r.m[0][1] = s.y; r.m[0][2] = s.z; r.m[0][3] = -dot(s, eye);
  r.m[1][0] = u.x; r.m[1][1] = u.y; r.m[1][2] = u.z; r.m[1][3] = -dot(u, eye);
  r.m[2][0] = -f.x; r.m[2][1] = -f.y; r.m[2][2] = -f.z; r.m[2][3] = dot(f, eye);
  return r;
}

Mat4 perspective(double fovy, double aspect, double n, double f) {
  const double cot = 1.0 / std::tan(fovy / 2);
  Mat4 r;
  r.m[0][0] = cot / aspect;
  r.m[1][1] = cot;
  // z_clip = f/(f-n) * (w - n) with w = -z_view: 0 at the near plane, w at the far plane.
  r.m[2][2] = -f / (f - n);
  r.m[2][3] = -f * n / (f - n);
  r.m[3][2] = -1;
  return r;
}

Mat4 orthographic(double l, double rt, double b, double t, double n, double f) {
  Mat4 r = identity();
  r.m[0][0] = 2 / (rt - l);
  r.m[0][3] = -(rt + l) / (rt - l);
  r.m[1][1] = 2 / (t - b);
  r.m[1][3] = -(t + b) / (t - b);
  r.m[2][2] = -1 / (f - n);
  r.m[2][3] = -n / (f - n);
  return r;
}

Mat4 viewport_matrix(const Viewport& vp) {
  // sx = vp.x + (ndc_x + 1) * width / 2, sy = vp.y + (1 - ndc_y) * height / 2, each times w;
  // z and w pass through (depth range [0, 1]).
  Mat4 r;
  r.m[0][0] = vp.width / 2;
  r.m[0][3] = vp.x + vp.width / 2;
  r.m[1][1] = -vp.height / 2;
  r.m[1][3] = vp.y + vp.height / 2;
  r.m[2][2] = 1;
  r.m[3][3] = 1;
  return r;
}

}  // namespace gpubridge::geometry
