#include "mesh.hpp"

#include <algorithm>
#include <cmath>

namespace gpubridge::examples {

void Mesh::quad(geometry::Vec3 a, geometry::Vec3 b, geometry::Vec3 c, geometry::Vec3 d, geometry::Vec4 color,
                geometry::Vec2 uv0, geometry::Vec2 uv1) {
  const auto base = static_cast<std::uint32_t>(vertices.size());
  vertices.emplace_back(a, color, geometry::Vec2{uv0.x, uv1.y});
  vertices.emplace_back(b, color, geometry::Vec2{uv1.x, uv1.y});
  vertices.emplace_back(c, color, geometry::Vec2{uv1.x, uv0.y});
  vertices.emplace_back(d, color, geometry::Vec2{uv0.x, uv0.y});
  for (std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) indices.push_back(base + k);
}

double hash01(std::uint32_t x, std::uint32_t y, std::uint32_t seed) {
  std::uint32_t h = x * 374761393u + y * 668265263u + seed * 2246822519u;
  h = (h ^ (h >> 13)) * 1274126177u;
  h ^= h >> 16;
  return (h & 0xFFFFFF) / 16777216.0;
}

double value_noise(double x, double y, std::uint32_t seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<std::uint32_t>(static_cast<std::int64_t>(fx)),
             iy = static_cast<std::uint32_t>(static_cast<std::int64_t>(fy));
  const double tx = x - fx, ty = y - fy;
  const double sx = tx * tx * (3 - 2 * tx), sy = ty * ty * (3 - 2 * ty);
  const double a = hash01(ix, iy, seed), b = hash01(ix + 1, iy, seed), c = hash01(ix, iy + 1, seed),
               d = hash01(ix + 1, iy + 1, seed);
  return (a * (1 - sx) + b * sx) * (1 - sy) + (c * (1 - sx) + d * sx) * sy;
}

double clamp01(double v) { return std::clamp(v, 0.0, 1.0); }

Image make_image(unsigned w, unsigned h) {
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.assign(std::size_t{w} * h * 4, 255);
  return img;
}

void put(Image& img, unsigned x, unsigned y, double r, double g, double b, double a) {
  auto* p = img.pixel(x, y);
  p[0] = static_cast<std::uint8_t>(std::lround(clamp01(r) * 255));
  p[1] = static_cast<std::uint8_t>(std::lround(clamp01(g) * 255));
  p[2] = static_cast<std::uint8_t>(std::lround(clamp01(b) * 255));
  p[3] = static_cast<std::uint8_t>(std::lround(clamp01(a) * 255));
}

Image checker_texture(unsigned size, unsigned cells, geometry::Vec4 a, geometry::Vec4 b) {
  Image img = make_image(size, size);
  const unsigned cell = size / cells;
  for (unsigned y = 0; y < size; ++y)
    for (unsigned x = 0; x < size; ++x) {
      const auto& c = ((x / cell + y / cell) % 2) ? b : a;
      put(img, x, y, c.x, c.y, c.z, c.w);
    }
  return img;
}

Image brick_texture(unsigned size) {
  Image img = make_image(size, size);
  const unsigned rows = 4, brick_h = size / rows, brick_w = size / 2, mortar = std::max(1u, size / 32);
  for (unsigned y = 0; y < size; ++y)
    for (unsigned x = 0; x < size; ++x) {
      const unsigned row = y / brick_h;
      const unsigned xo = (x + (row % 2) * brick_w / 2) % size;
      const bool is_mortar = (y % brick_h) < mortar || (xo % brick_w) < mortar;
      const double n = 0.85 + 0.15 * value_noise(x * 0.5, y * 0.5, 7);
      const double tint = 0.9 + 0.2 * hash01(xo / brick_w, row, 3);
      if (is_mortar)
        put(img, x, y, 0.75 * n, 0.73 * n, 0.68 * n);
      else
        put(img, x, y, 0.62 * n * tint, 0.26 * n * tint, 0.18 * n * tint);
    }
  return img;
}

}  // namespace gpubridge::examples
