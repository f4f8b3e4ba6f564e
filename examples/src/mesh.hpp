#pragma once
// Procedural meshes and textures shared by the examples.
#include <cstdint>
#include <vector>

#include "gpubridge/common/image.hpp"
#include "gpubridge/draw/context.hpp"

namespace gpubridge::examples {

struct Mesh {
  std::vector<draw::Vertex> vertices;
  std::vector<std::uint32_t> indices;

  // Appends a quad a-b-c-d (counter-clockwise seen from the front) with texture corners
  // (u0,v0)-(u1,v1) as two triangles.
  void quad(geometry::Vec3 a, geometry::Vec3 b, geometry::Vec3 c, geometry::Vec3 d, geometry::Vec4 color,
            geometry::Vec2 uv0 = {0, 0}, geometry::Vec2 uv1 = {1, 1});
};

// Integer hash → [0, 1): deterministic noise for textures and terrain.
double hash01(std::uint32_t x, std::uint32_t y, std::uint32_t seed = 0);
// Smooth value noise in [0, 1) with integer lattice spacing 1.
double value_noise(double x, double y, std::uint32_t seed = 0);

Image make_image(unsigned w, unsigned h);
void put(Image& img, unsigned x, unsigned y, double r, double g, double b, double a = 1.0);

Image checker_texture(unsigned size, unsigned cells, geometry::Vec4 a, geometry::Vec4 b);
Image brick_texture(unsigned size);

double clamp01(double v);

}  // namespace gpubridge::examples
