// DMC-1 / Comanche: a height-map terrain flown over, with one planar colour map projected from
// above (u = x / size, v = z / size) and sampled perspective-correctly.
#include <cmath>

#include "examples_internal.hpp"
#include "fallbacks.hpp"
#include "mesh.hpp"
#include "terrain_lod.hpp"

namespace gpubridge::examples {
namespace {

constexpr int kGrid = 64;        // vertices per side
constexpr double kCell = 1.0;    // world units per cell
constexpr double kSize = (kGrid - 1) * kCell;
constexpr unsigned kTex = 256;   // colour map texels per side
// Level of detail: a 2x2-cell block whose centre is farther than this from the eye (across the
// ground) is drawn from its corners, as one cell twice the size: about 15 pixels across there and 5
// at the far plane (320x240, the projection below), where the colour map carries the detail. It
// halves what a frame sends (docs/daemon.md "Remote benchmark": 60 fps within 20 Mbit/s).
constexpr double kLodDistance = 30.0;

double height_at(double x, double z) {
  return 7.0 * value_noise(x / 9.0, z / 9.0, 11) + 2.5 * value_noise(x / 3.5, z / 3.5, 12) - 2.0;
}

class Terrain final : public Example {
 public:
  ExampleInfo info() const override {
    return {"terrain", "DMC-1 (Comanche)", "a height-map terrain fly-over with a planar perspective-correct colour map"};
  }
  Wants wants(std::uint16_t) const override {
    Wants w;
    w.format = protocol::PixelFormat::RGB565;
    w.textures = {{"colour map", kTex, kTex, protocol::PixelFormat::RGB565}};
    // The colour map is what the fly-over shows: its detail outlasts the framebuffer's bits.
    w.keep = {Knob::Size, Knob::Textures, Knob::Format, Knob::DoubleBuffer, Knob::Depth};
    w.without_depth = "cells drawn far to near (exact for a height field)";
    w.without_feature = {{kTexturing, "the colour map baked into the vertex colours"}};
    return w;
  }

  Result<void> setup(draw::Context& ctx) override {
    mesh_ = {};
    texture_ = {};
    // The colour map: height bands shaded by the slope towards the light, like Comanche's voxel map.
    Image map = make_image(kTex, kTex);
    for (unsigned j = 0; j < kTex; ++j)
      for (unsigned i = 0; i < kTex; ++i) {
        const double x = (i + 0.5) / kTex * kSize, z = (j + 0.5) / kTex * kSize;
        const double h = height_at(x, z);
        const double shade = 0.75 + 0.6 * (height_at(x - 0.3, z - 0.3) - h);
        geometry::Vec3 c;
        if (h < 0.2) c = {0.15, 0.3, 0.6};
        else if (h < 1.0) c = {0.75, 0.7, 0.45};
        else if (h < 4.2) c = {0.25 + 0.1 * value_noise(x, z, 5), 0.55, 0.2};
        else if (h < 6.0) c = {0.5, 0.45, 0.4};
        else c = {0.95, 0.95, 0.97};
        put(map, i, j, c.x * shade, c.y * shade, c.z * shade);
      }
    if (config().texturing()) {
      auto t = ctx.create_texture(config().texture(0).shrink(map), config().texture(0).options(protocol::Wrap::Clamp, protocol::Wrap::Clamp));
      if (!t) return t.error();
      texture_ = *t;
    }
    for (int j = 0; j < kGrid; ++j)
      for (int i = 0; i < kGrid; ++i) {
        const double x = i * kCell, z = j * kCell;
        mesh_.vertices.emplace_back(geometry::Vec3{x, std::max(0.2, height_at(x, z)), z}, geometry::Vec4{1, 1, 1, 1},
                                    geometry::Vec2{x / kSize, z / kSize});
      }
    for (int j = 0; j + 1 < kGrid; ++j)
      for (int i = 0; i + 1 < kGrid; ++i) {
        const std::uint32_t a = j * kGrid + i, b = a + 1, c = a + kGrid, d = c + 1;
        // Counter-clockwise seen from above (+y).
        for (std::uint32_t k : {a, c, b, b, c, d}) mesh_.indices.push_back(k);
      }
    if (!config().texturing()) mesh_ = bake_texture(mesh_, map, 1, false, protocol::Wrap::Clamp, protocol::Wrap::Clamp);
    return {};
  }

  Result<void> frame(draw::Context& ctx, unsigned n) override {
    if (auto r = begin_frame(ctx, config(), {0.55, 0.72, 0.95, 1}); !r) return r;
    ctx.set_cull(geometry::CullMode::Back);
    // Fly north along a gentle curve, keeping above the ground.
    const double t = n * 0.35;
    const double cz = kSize - 4 - t, cx = kSize / 2 + 6 * std::sin(t * 0.08);
    const double cy = std::max(height_at(cx, cz), 0.2) + 4.0;
    const geometry::Vec3 eye{cx, cy, cz}, target{cx + 2 * std::sin(t * 0.08 + 0.3), cy - 1.6, cz - 6};
    ctx.set_transform(projection(ctx, 1.0, 0.3, 80) * geometry::look_at(eye, target, {0, 1, 0}));
    if (config().texturing()) {
      if (auto r = ctx.bind_texture(texture_); !r) return r;
    } else {
      ctx.unbind_texture();
    }
    if (config().painter()) return ctx.draw_indexed(mesh_.vertices, painter_order(eye));
    // Far blocks coarser (the grid's own vertices, so textured only: a baked mesh has its own).
    if (config().texturing())
      return ctx.draw_indexed(mesh_.vertices, terrain_lod_indices(kGrid, eye.x / kCell, eye.z / kCell, kLodDistance / kCell));
    return ctx.draw_indexed(mesh_.vertices, mesh_.indices);
  }

 private:
  // The cells far to near from the eye (by the distance of their centres across the ground: the
  // cells are the Voronoi regions of those centres, so no cell can hide a farther one), and in
  // each cell the triangle beyond the diagonal from the eye first. Six indices per cell, as
  // setup() lists them (a c b, b c d; the diagonal b-c), baked or not (one cut keeps them).
  std::vector<std::uint32_t> painter_order(geometry::Vec3 eye) const {
    struct Cell {
      double distance;
      std::uint32_t first;  // index of its first index
      bool near_side_d;     // the eye is on corner d's side of the diagonal
    };
    std::vector<Cell> cells;
    cells.reserve(mesh_.indices.size() / 6);
    for (int j = 0; j + 1 < kGrid; ++j)
      for (int i = 0; i + 1 < kGrid; ++i) {
        const double dx = (i + 0.5) * kCell - eye.x, dz = (j + 0.5) * kCell - eye.z;
        const bool d_side = eye.x + eye.z > (i + j + 1) * kCell;
        cells.push_back({dx * dx + dz * dz, static_cast<std::uint32_t>((j * (kGrid - 1) + i) * 6), d_side});
      }
    std::stable_sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.distance > b.distance; });
    std::vector<std::uint32_t> out;
    out.reserve(mesh_.indices.size());
    for (const auto& c : cells) {
      const std::uint32_t far = c.near_side_d ? c.first : c.first + 3, near = c.near_side_d ? c.first + 3 : c.first;
      out.insert(out.end(), mesh_.indices.begin() + far, mesh_.indices.begin() + far + 3);
      out.insert(out.end(), mesh_.indices.begin() + near, mesh_.indices.begin() + near + 3);
    }
    return out;
  }

  draw::Texture texture_;
  Mesh mesh_;
};

}  // namespace

std::unique_ptr<Example> make_terrain() { return std::make_unique<Terrain>(); }

}  // namespace gpubridge::examples
