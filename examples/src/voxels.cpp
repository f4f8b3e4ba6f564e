// FmcPGA: a voxel chunk (grass, dirt, stone) with alpha-blended water, drawn into alternating
// buffers (double buffering: the displayed frame is never the one being drawn).
#include <cmath>

#include "examples_internal.hpp"
#include "fallbacks.hpp"
#include "mesh.hpp"

namespace gpubridge::examples {
namespace {

constexpr int kN = 16, kH = 9, kWater = 4;
enum Block : std::uint8_t { Air, Grass, Dirt, Stone, Water };

class Voxels final : public Example {
 public:
  ExampleInfo info() const override {
    return {"voxels", "FmcPGA", "a voxel chunk with alpha-blended water, double-buffered"};
  }
  Wants wants(std::uint16_t) const override {
    Wants w;
    w.textures = {{"atlas", 64, 64, protocol::PixelFormat::RGBA8888}};
    // Double buffering is the idea (the displayed frame is never the one being drawn).
    w.keep = {Knob::DoubleBuffer, Knob::Size, Knob::Format, Knob::Textures, Knob::Depth};
    w.without_depth = "blocks drawn far to near (exact on a grid), the water blended in the same order";
    w.without_feature = {{kBlend, "the water drawn opaque"}, {kTexturing, "each face in its tile's mean colour"}};
    return w;
  }

  Result<void> setup(draw::Context& ctx) override {
    solid_ = {};
    water_ = {};
    solid_cells_.clear();
    water_cells_.clear();
    atlas_ = {};
    // Atlas 64x64: four 32x32 tiles (grass top, dirt, stone, water).
    Image atlas = make_image(64, 64);
    for (unsigned y = 0; y < 64; ++y)
      for (unsigned x = 0; x < 64; ++x) {
        const unsigned tile = (y / 32) * 2 + x / 32;
        const double n = hash01(x, y, 21), m = value_noise(x / 4.0, y / 4.0, 22);
        switch (tile) {
          case 0: put(atlas, x, y, 0.25 + 0.15 * n, 0.6 + 0.25 * m, 0.2); break;
          case 1: put(atlas, x, y, 0.5 + 0.15 * n, 0.35 + 0.1 * m, 0.2); break;
          case 2: put(atlas, x, y, 0.5 + 0.2 * n * m, 0.5 + 0.2 * n * m, 0.52 + 0.2 * n * m); break;
          default: put(atlas, x, y, 0.2, 0.4 + 0.2 * m, 0.85, 1.0); break;
        }
      }
    geometry::Vec4 tile_mean[4];
    if (config().texturing()) {
      auto t = ctx.create_texture(config().texture(0).shrink(atlas), config().texture(0).options());
      if (!t) return t.error();
      atlas_ = *t;
    } else {
      // Without a texture unit each face takes its tile's mean colour (the 2x2 level of the atlas).
      const Image means = TextureFit{"", 2, 2}.shrink(atlas);
      for (int k = 0; k < 4; ++k) {
        const auto* p = means.pixel(k % 2, k / 2);
        tile_mean[k] = {p[0] / 255.0, p[1] / 255.0, p[2] / 255.0, p[3] / 255.0};
      }
    }
    const auto tint = [&](int tile, geometry::Vec4 c) {
      if (config().texturing()) return c;
      const auto& m = tile_mean[tile];
      return geometry::Vec4{c.x * m.x, c.y * m.y, c.z * m.z, c.w * m.w};
    };
    // The chunk: column heights from noise; water fills low columns up to kWater.
    Block w[kN][kH][kN] = {};
    for (int x = 0; x < kN; ++x)
      for (int z = 0; z < kN; ++z) {
        const int h = 1 + static_cast<int>(7.5 * value_noise(x / 5.0, z / 5.0, 23));
        for (int y = 0; y < kH; ++y) {
          Block b = Air;
          if (y < h - 2) b = Stone;
          else if (y < h - 1) b = Dirt;
          else if (y < h) b = (h - 1 >= kWater) ? Grass : Dirt;
          else if (y < kWater) b = Water;
          w[x][y][z] = b;
        }
      }
    auto at = [&](int x, int y, int z) -> Block {
      if (x < 0 || y < 0 || z < 0 || x >= kN || y >= kH || z >= kN) return Air;
      return w[x][y][z];
    };
    // Faces of solid blocks next to air or water; water top faces only where air is above.
    struct Face {
      int dx, dy, dz;
      double shade;
    };
    const Face faces[6] = {{0, 1, 0, 1.0}, {0, -1, 0, 0.5}, {1, 0, 0, 0.8}, {-1, 0, 0, 0.7}, {0, 0, 1, 0.85}, {0, 0, -1, 0.65}};
    for (int x = 0; x < kN; ++x)
      for (int y = 0; y < kH; ++y)
        for (int z = 0; z < kN; ++z) {
          const Block b = w[x][y][z];
          if (b == Air) continue;
          for (const auto& f : faces) {
            const Block nb = at(x + f.dx, y + f.dy, z + f.dz);
            const geometry::Vec3 cell{x + 0.5, y + 0.5, z + 0.5};
            if (b == Water) {
              if (f.dy == 1 && nb == Air) {
                add_face(water_, x, y, z, f.dx, f.dy, f.dz, 3, tint(3, {0.9, 0.95, 1, 0.55}));
                water_cells_.push_back(cell);
              }
              continue;
            }
            if (nb != Air && nb != Water) continue;
            const int tile = b == Grass ? (f.dy == 1 ? 0 : 1) : b == Dirt ? 1 : 2;
            add_face(solid_, x, y, z, f.dx, f.dy, f.dz, tile, tint(tile, {f.shade, f.shade, f.shade, 1}));
            solid_cells_.push_back(cell);
          }
        }
    return {};
  }

  Result<void> frame(draw::Context& ctx, unsigned n) override {
    if (auto r = begin_frame(ctx, config(), {0.62, 0.8, 1.0, 1}); !r) return r;
    const double a = 0.6 + n * 0.05;
    const geometry::Vec3 centre{kN / 2.0, 2.5, kN / 2.0};
    const geometry::Vec3 eye{centre.x + 17 * std::cos(a), 13, centre.z + 17 * std::sin(a)};
    ctx.set_transform(projection(ctx, 0.9, 0.5, 60) * geometry::look_at(eye, centre, {0, 1, 0}));
    if (config().texturing()) {
      if (auto r = ctx.bind_texture(atlas_); !r) return r;
    } else {
      ctx.unbind_texture();
    }
    ctx.set_cull(geometry::CullMode::Back);
    const auto water_blend = config().has(kBlend) ? protocol::BlendMode::Alpha : protocol::BlendMode::Off;
    if (config().painter()) return draw_far_to_near(ctx, eye, water_blend);
    // Opaque blocks first, writing depth; then the water, blended, tested but not written.
    if (auto r = ctx.draw_indexed(solid_.vertices, solid_.indices); !r) return r;
    ctx.state().z_write = false;
    ctx.state().blend = water_blend;
    return ctx.draw_indexed(water_.vertices, water_.indices);
  }

 private:
  static void add_face(Mesh& m, int x, int y, int z, int dx, int dy, int dz, int tile, geometry::Vec4 color) {
    // The face with outward normal n = (dx, dy, dz): corners o ∓ u/2 ∓ v/2 with u × v = n, listed
    // counter-clockwise seen from outside.
    const geometry::Vec3 c{x + 0.5, y + 0.5, z + 0.5};
    const geometry::Vec3 nrm{double(dx), double(dy), double(dz)};
    const geometry::Vec3 u = dy != 0 ? geometry::Vec3{1, 0, 0} : geometry::Vec3{0, 1, 0};
    const geometry::Vec3 v = geometry::cross(nrm, u);
    const geometry::Vec3 o = c + nrm * 0.5;
    // Tile rectangle in the atlas, inset by half a texel so nearest sampling never bleeds.
    const double tu = (tile % 2) * 0.5 + 0.5 / 64, tv = (tile / 2) * 0.5 + 0.5 / 64, ts = 0.5 - 1.0 / 64;
    const double water_drop = (tile == 3) ? -0.15 : 0.0;
    const geometry::Vec3 d{0, water_drop, 0};
    m.quad(o - u * 0.5 - v * 0.5 + d, o + u * 0.5 - v * 0.5 + d, o + u * 0.5 + v * 0.5 + d, o - u * 0.5 + v * 0.5 + d, color,
           {tu, tv}, {tu + ts, tv + ts});
  }

  // Painter's order: every face with its block's cell, cells far to near from the eye. The cells
  // are the Voronoi regions of their centres, so ordering by that distance never draws a cell
  // over one in front of it; within a cell the culled cube's faces do not overlap. The water
  // blends over whatever was drawn behind it, as with the depth buffer.
  Result<void> draw_far_to_near(draw::Context& ctx, geometry::Vec3 eye, protocol::BlendMode water_blend) {
    struct Face {
      double distance;
      bool water;
      std::uint32_t index;  // face number in its mesh (six indices each)
    };
    std::vector<Face> faces;
    faces.reserve(solid_cells_.size() + water_cells_.size());
    const auto dist2 = [&](geometry::Vec3 c) { return geometry::dot(c - eye, c - eye); };
    for (std::uint32_t i = 0; i < solid_cells_.size(); ++i) faces.push_back({dist2(solid_cells_[i]), false, i});
    for (std::uint32_t i = 0; i < water_cells_.size(); ++i) faces.push_back({dist2(water_cells_[i]), true, i});
    std::stable_sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) { return a.distance > b.distance; });
    // Runs of solid or water faces, each one draw with its state.
    std::vector<std::uint32_t> run;
    for (std::size_t i = 0; i < faces.size();) {
      const bool water = faces[i].water;
      const Mesh& m = water ? water_ : solid_;
      run.clear();
      for (; i < faces.size() && faces[i].water == water; ++i)
        run.insert(run.end(), m.indices.begin() + faces[i].index * 6, m.indices.begin() + faces[i].index * 6 + 6);
      ctx.state().blend = water ? water_blend : protocol::BlendMode::Off;
      if (auto r = ctx.draw_indexed(m.vertices, run); !r) return r;
    }
    return {};
  }

  draw::Texture atlas_;
  Mesh solid_, water_;
  std::vector<geometry::Vec3> solid_cells_, water_cells_;  // the block of each face, one per quad
};

}  // namespace

std::unique_ptr<Example> make_voxels() { return std::make_unique<Voxels>(); }

}  // namespace gpubridge::examples
