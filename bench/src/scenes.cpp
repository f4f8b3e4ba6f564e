// Scene generators of `gpubridge bench accuracy` (see scenes.hpp). Fixed seeds: every run renders
// the same triangles.
#include "gpubridge/bench/scenes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace gpubridge::bench {
namespace {

using geometry::ScreenVertex;
using HostTri = std::array<ScreenVertex, 3>;

// A random triangle of the given area, fully inside the target, with no angle below ~15 degrees.
HostTri random_triangle(std::mt19937& rng, double area, double width, double height) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (;;) {
    const double a0 = unit(rng) * 2 * std::numbers::pi;
    const double a1 = a0 + (0.6 + unit(rng) * 1.6);
    const double a2 = a1 + (0.6 + unit(rng) * 1.6);
    HostTri t;
    const double angles[3] = {a0, a1, a2};
    for (int i = 0; i < 3; ++i) t[i].x = std::cos(angles[i]), t[i].y = std::sin(angles[i]);
    const double a = std::fabs((t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y)) / 2;
    if (a < 0.3 || 2 * std::numbers::pi - (a2 - a0) < 0.6) continue;
    const double k = std::sqrt(area / a);
    double lo_x = 1e9, hi_x = -1e9, lo_y = 1e9, hi_y = -1e9;
    for (auto& v : t) {
      v.x *= k, v.y *= k;
      lo_x = std::min(lo_x, v.x), hi_x = std::max(hi_x, v.x), lo_y = std::min(lo_y, v.y), hi_y = std::max(hi_y, v.y);
    }
    if (hi_x - lo_x >= width - 1 || hi_y - lo_y >= height - 1) continue;
    const double ox = unit(rng) * (width - (hi_x - lo_x)) - lo_x, oy = unit(rng) * (height - (hi_y - lo_y)) - lo_y;
    for (auto& v : t) {
      v.x += ox, v.y += oy;
      v.color = {unit(rng), unit(rng), unit(rng), 1.0};
    }
    return t;
  }
}

Result<void> add(Scene& s, const HostTri& t) {
  geometry::TexAddressing tex;
  auto d = geometry::convert_triangle(t, tex);
  if (!d) return make_error("scene " + s.name + ": " + d.error().message);
  s.triangles.push_back(*d);
  return {};
}

Result<Scene> gouraud_scene(const std::string& name, double area, std::size_t count, bool front, std::size_t subset,
                            unsigned seed) {
  Scene s;
  s.name = name;
  s.description = std::to_string(count) + " random Gouraud triangles of " + std::to_string(int(area)) + " px, Z " +
                  (front ? "front (each nearer than all earlier: every pixel passes)" : "random (most pixels rejected)") +
                  ", depth LESS";
  s.state.z_test = true;
  s.state.z_write = true;
  s.state.z_func = protocol::DepthFunc::Less;
  s.nominal_area = area;
  s.error_subset = std::min(subset, count);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t i = 0; i < count; ++i) {
    HostTri t = random_triangle(rng, area, s.width, s.height);
    for (auto& v : t) v.z = front ? 1.0 - double(i + 1) / double(count + 1) : unit(rng);
    if (auto r = add(s, t); !r) return r.error();
  }
  return s;
}

// A road receding to the horizon: a textured strip whose W grows from 1 to 40, split into rows so
// each triangle's W ratio stays small (the host rule of docs section 15).
Result<Scene> road_scene(unsigned repeats) {
  Scene s;
  s.name = "road";
  s.description = "perspective-textured road (W 1..40, 1024x1024 texture, bilinear), " + std::to_string(repeats) +
                  " passes, depth LEQUAL";
  s.textured = true;
  s.state.textured = true;
  s.state.tex_decal = true;
  s.state.z_test = true;
  s.state.z_write = true;
  s.state.z_func = protocol::DepthFunc::LessEqual;
  const int rows = 48, cols = 4;
  const double horizon = 200, bottom = 480, near_w = 1, far_w = 40;
  // Rows are evenly spaced in 1/W (screen-linear), so each row's screen height is equal.
  auto row_w = [&](int r) { return 1.0 / (1.0 / near_w + (1.0 / far_w - 1.0 / near_w) * r / rows); };
  for (unsigned rep = 0; rep < repeats; ++rep)
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        auto vertex = [&](int rr, int cc) {
          const double w = row_w(rr);
          const double y = bottom - (bottom - horizon) * rr / rows;
          const double half = 400.0 / w + 20;  // road half-width on screen shrinks with distance
          ScreenVertex v;
          v.x = 320 + half * (2.0 * cc / cols - 1.0);
          v.y = std::min(y, 479.9);
          v.z = 1.0 - 1.0 / w;
          v.w = w;
          v.uv = {double(cc) / cols * 2.0, w / far_w * 3.0};  // v grows with distance (world-linear)
          v.color = {1, 1, 1, 1};
          return v;
        };
        const ScreenVertex a = vertex(r, c), b = vertex(r, c + 1), cc = vertex(r + 1, c + 1), d = vertex(r + 1, c);
        if (auto e = add(s, {a, b, cc}); !e) return e.error();
        if (auto e = add(s, {a, cc, d}); !e) return e.error();
      }
  s.error_subset = s.triangles.size() / repeats;
  return s;
}

// A grid of rotating textured cubes in perspective, depth LESS.
Result<Scene> cube_scene(unsigned count) {
  Scene s;
  s.name = "cubes";
  s.description = std::to_string(count) + " perspective-textured cubes (12 triangles each), depth LESS";
  s.textured = true;
  s.state.textured = true;
  s.state.tex_decal = true;
  s.state.z_test = true;
  s.state.z_write = true;
  s.state.z_func = protocol::DepthFunc::Less;
  static const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  const unsigned grid = std::max(1u, unsigned(std::ceil(std::sqrt(double(count)))));
  for (unsigned n = 0; n < count; ++n) {
    const double angle = 0.37 * n + 0.2, tilt = 0.5 + 0.11 * n;
    const double cx = (n % grid + 0.5) / grid * 2 - 1, cy = (n / grid + 0.5) / grid * 2 - 1;
    ScreenVertex v[8];
    for (int i = 0; i < 8; ++i) {
      double x = (i & 1) ? 0.5 : -0.5, y = (i & 2) ? 0.5 : -0.5, z = (i & 4) ? 0.5 : -0.5;
      const double x1 = x * std::cos(angle) - z * std::sin(angle), z1 = x * std::sin(angle) + z * std::cos(angle);
      const double y1 = y * std::cos(tilt) - z1 * std::sin(tilt), z2 = y * std::sin(tilt) + z1 * std::cos(tilt);
      const double w = 3.0 + z2 * 1.6;  // distance from the eye
      const double spread = 2.2 * grid / 2.0;
      v[i].w = w;
      v[i].x = 320 + (x1 + cx * spread) * 600 / (w * grid);
      v[i].y = 240 + (y1 + cy * spread) * 600 / (w * grid) * 0.75;
      v[i].z = 1.0 - 1.0 / w;
    }
    for (const auto& f : faces) {
      ScreenVertex q[4];
      const double uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      for (int k = 0; k < 4; ++k) {
        q[k] = v[f[k]];
        q[k].uv = {uv[k][0], uv[k][1]};
      }
      if (auto e = add(s, {q[0], q[1], q[2]}); !e) return e.error();
      if (auto e = add(s, {q[0], q[2], q[3]}); !e) return e.error();
    }
  }
  s.error_subset = s.triangles.size();
  return s;
}

Result<Scene> fan_scene(unsigned repeats) {
  Scene s;
  s.name = "fan";
  s.description = "720-triangle Gouraud fan around a pixel centre (r = 200 px), " + std::to_string(repeats) + " passes";
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (unsigned rep = 0; rep < repeats; ++rep)
    for (int i = 0; i < 720; ++i) {
      HostTri t;
      const double a0 = 2 * std::numbers::pi * i / 720, a1 = 2 * std::numbers::pi * (i + 1) / 720;
      t[0].x = 320.5, t[0].y = 240.5;
      t[1].x = 320.5 + 200 * std::cos(a0), t[1].y = 240.5 + 200 * std::sin(a0);
      t[2].x = 320.5 + 200 * std::cos(a1), t[2].y = 240.5 + 200 * std::sin(a1);
      for (auto& v : t) v.color = {unit(rng), unit(rng), unit(rng), 1}, v.z = 0.5;
      if (auto e = add(s, t); !e) return e.error();
    }
  s.error_subset = 720;
  return s;
}

Result<Scene> blend_scene(std::size_t count) {
  Scene s;
  s.name = "alpha-blend";
  s.description = std::to_string(count) + " Gouraud triangles of 1,000 px, alpha 0.5, BLEND ALPHA, no depth test";
  s.state.blend = protocol::BlendMode::Alpha;
  s.nominal_area = 1000;
  std::mt19937 rng(9);
  for (std::size_t i = 0; i < count; ++i) {
    HostTri t = random_triangle(rng, 1000, s.width, s.height);
    for (auto& v : t) v.color.w = 0.5, v.z = 0.5;
    if (auto e = add(s, t); !e) return e.error();
  }
  s.error_subset = std::min<std::size_t>(count, 2000);
  return s;
}

}  // namespace

Result<std::vector<Scene>> make_scenes(unsigned scale) {
  if (scale == 0) return make_error("scene scale must be >= 1");
  std::vector<Scene> out;
  auto push = [&](Result<Scene> s) -> Result<void> {
    if (!s) return s.error();
    out.push_back(std::move(s).value());
    return {};
  };
  const std::size_t small = 500000 / scale, medium = 50000 / scale, large = std::max<std::size_t>(2000 / scale, 10);
  for (bool front : {true, false}) {
    const char* z = front ? "front" : "random";
    if (auto r = push(gouraud_scene(std::string("tri10-") + z, 10, small, front, 20000, front ? 1 : 2)); !r) return r.error();
    if (auto r = push(gouraud_scene(std::string("tri1k-") + z, 1000, medium, front, 2000, front ? 3 : 4)); !r) return r.error();
    if (auto r = push(gouraud_scene(std::string("tri50k-") + z, 50000, large, front, 40, front ? 5 : 6)); !r) return r.error();
  }
  if (auto r = push(road_scene(std::max(1u, 20 / scale))); !r) return r.error();
  if (auto r = push(cube_scene(std::max(1u, 64 / scale))); !r) return r.error();
  if (auto r = push(fan_scene(std::max(1u, 20 / scale))); !r) return r.error();
  if (auto r = push(blend_scene(std::max<std::size_t>(2000 / scale, 40))); !r) return r.error();
  return out;
}

}  // namespace gpubridge::bench
