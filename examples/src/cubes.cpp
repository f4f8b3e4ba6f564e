// ICEpi: a Gouraud-shaded cube next to a textured one (the register protocol's two basic paths).
#include <cmath>

#include "examples_internal.hpp"
#include "fallbacks.hpp"
#include "mesh.hpp"

namespace gpubridge::examples {
namespace {

// A cube of half-size 1: 4 vertices per face (own UVs), counter-clockwise from outside.
Mesh cube_mesh(bool corner_colors) {
  Mesh m;
  const geometry::Vec3 normals[6] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
  for (const auto& n : normals) {
    const geometry::Vec3 u = std::abs(n.y) > 0 ? geometry::Vec3{1, 0, 0} : geometry::Vec3{0, 1, 0};
    const geometry::Vec3 v = geometry::cross(n, u);
    // Corners n ∓ u ∓ v with u × v = n: counter-clockwise from outside.
    const geometry::Vec3 p[4] = {n - u - v, n + u - v, n + u + v, n - u + v};
    const geometry::Vec2 t[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    for (int k = 0; k < 4; ++k) {
      const geometry::Vec4 c = corner_colors ? geometry::Vec4{(p[k].x + 1) / 2, (p[k].y + 1) / 2, (p[k].z + 1) / 2, 1}
                                             : geometry::Vec4{1, 1, 1, 1};
      m.vertices.emplace_back(p[k], c, t[k]);
    }
    for (std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + k);
  }
  return m;
}

class Cubes final : public Example {
 public:
  ExampleInfo info() const override {
    return {"cubes", "ICEpi SPI GPU",
            "a Gouraud-shaded cube and a bilinear-textured cube, rotating; the texture is re-uploaded every frame"};
  }

  // The 32x32 label: a border and a ring whose lit quarter turns by one step per frame.
  static Image label(unsigned n) {
    Image img = make_image(32, 32);
    for (unsigned y = 0; y < 32; ++y)
      for (unsigned x = 0; x < 32; ++x) {
        const bool border = x < 2 || y < 2 || x > 29 || y > 29;
        const double dx = x - 15.5, dy = y - 15.5;
        const double d = std::hypot(dx, dy);
        const bool ring = d > 7 && d < 10;
        // Quadrant of the pixel (0..3, counter-clockwise from +x) against the frame's lit quadrant.
        const unsigned quadrant = dx >= 0 ? (dy >= 0 ? 0u : 3u) : (dy >= 0 ? 1u : 2u);
        const bool lit = ring && quadrant == n % 4;
        put(img, x, y, border ? 0.1 : lit ? 1.0 : ring ? 0.6 : 0.9, border ? 0.1 : lit ? 0.85 : ring ? 0.3 : 0.9,
            border ? 0.15 : lit ? 0.2 : ring ? 0.1 : 0.85);
      }
    return img;
  }

  Wants wants(std::uint16_t) const override {
    Wants w;
    w.textures = {{"label", 32, 32, protocol::PixelFormat::RGBA8888, true}};
    w.without_depth = "the two cubes one after the other (each convex, back faces culled; they do not overlap)";
    w.without_feature = {{kBilinear, "the label sampled nearest"},
                         {kTexturing, "the label baked into the cube's vertex colours every frame"}};
    return w;
  }

  Result<void> setup(draw::Context& ctx) override {
    texture_ = {};
    if (config().texturing()) {
      auto t = ctx.create_texture(config().texture(0).shrink(label(0)), config().texture(0).options());
      if (!t) return t.error();
      texture_ = *t;
    }
    gouraud_ = cube_mesh(true);
    textured_ = cube_mesh(false);
    return {};
  }

  Result<void> frame(draw::Context& ctx, unsigned n) override {
    // The textured cube's label is streamed: a new image every frame, uploaded in place (baked
    // into the cube's colours without a texture unit).
    if (config().texturing()) {
      if (auto r = ctx.update_texture(texture_, config().texture(0).shrink(label(n))); !r) return r;
    } else {
      baked_ = bake_texture(textured_, label(n), 8);
    }
    if (auto r = begin_frame(ctx, config(), {0.12, 0.1, 0.16, 1}); !r) return r;
    ctx.set_cull(geometry::CullMode::Back);
    const double t = n * 0.08;
    const auto vp = projection(ctx, 0.8, 0.5, 30) * geometry::look_at({0, 1.2, 7}, {0, 0, 0}, {0, 1, 0});
    ctx.set_transform(vp * geometry::translate({-1.7, 0, 0}) * geometry::rotate_y(t) * geometry::rotate_x(t * 0.7));
    ctx.unbind_texture();
    if (auto r = ctx.draw_indexed(gouraud_.vertices, gouraud_.indices); !r) return r;
    ctx.set_transform(vp * geometry::translate({1.7, 0, 0}) * geometry::rotate_y(-t * 0.8) * geometry::rotate_z(t * 0.5));
    if (!config().texturing()) return ctx.draw_indexed(baked_.vertices, baked_.indices);
    if (auto r = ctx.bind_texture(texture_); !r) return r;
    return ctx.draw_indexed(textured_.vertices, textured_.indices);
  }

 private:
  draw::Texture texture_;
  Mesh gouraud_, textured_, baked_;
};

}  // namespace

std::unique_ptr<Example> make_cubes() { return std::make_unique<Cubes>(); }

}  // namespace gpubridge::examples
