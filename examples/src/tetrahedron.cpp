// DMC-1: a rotating textured tetrahedron (perspective-correct texturing, depth test, culling).
#include <cmath>
#include <numbers>

#include "examples_internal.hpp"
#include "fallbacks.hpp"
#include "mesh.hpp"

namespace gpubridge::examples {
namespace {

class Tetrahedron final : public Example {
 public:
  ExampleInfo info() const override {
    return {"tetrahedron", "DMC-1", "a rotating tetrahedron with a perspective-correct procedural texture on each face"};
  }
  Wants wants(std::uint16_t) const override {
    Wants w;
    w.format = protocol::PixelFormat::RGB565;
    w.textures = {{"checker", 64, 64, protocol::PixelFormat::RGB565}};
    // The perspective-correct texture is the idea: its detail outlasts the framebuffer's bits.
    w.keep = {Knob::Size, Knob::Textures, Knob::Format, Knob::DoubleBuffer, Knob::Depth};
    w.without_depth = "nothing: a convex solid with its back faces culled needs no depth test";
    w.without_feature = {{kTexturing, "the texture's colours baked into faces cut 4 x 4 (its fine checker averages out)"}};
    return w;
  }

  Result<void> setup(draw::Context& ctx) override {
    mesh_ = {};
    texture_ = {};
    // A 64x64 texture: a checkerboard with a diagonal stripe, so perspective errors would show.
    Image img = make_image(64, 64);
    for (unsigned y = 0; y < 64; ++y)
      for (unsigned x = 0; x < 64; ++x) {
        const bool check = ((x / 8) + (y / 8)) % 2 == 0;
        const bool stripe = (x + y) % 32 < 4;
        const double v = stripe ? 1.0 : check ? 0.85 : 0.35;
        put(img, x, y, v, v * (stripe ? 0.9 : 1.0), stripe ? 0.2 : v);
      }
    if (config().texturing()) {
      auto t = ctx.create_texture(config().texture(0).shrink(img), config().texture(0).options());
      if (!t) return t.error();
      texture_ = *t;
    }
    // Regular tetrahedron: every face counter-clockwise from outside, one colour tint each.
    const geometry::Vec3 p[4] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
    const int faces[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
    const geometry::Vec4 tint[4] = {{1, 0.5, 0.5, 1}, {0.5, 1, 0.5, 1}, {0.5, 0.6, 1, 1}, {1, 1, 0.5, 1}};
    for (int f = 0; f < 4; ++f) {
      geometry::Vec3 a = p[faces[f][0]], b = p[faces[f][1]], c = p[faces[f][2]];
      // Make the winding counter-clockwise seen from outside (normal pointing away from the centre).
      if (geometry::dot(geometry::cross(b - a, c - a), a + b + c) < 0) std::swap(b, c);
      const auto base = static_cast<std::uint32_t>(mesh_.vertices.size());
      mesh_.vertices.emplace_back(a, tint[f], geometry::Vec2{0, 0});
      mesh_.vertices.emplace_back(b, tint[f], geometry::Vec2{2, 0});
      mesh_.vertices.emplace_back(c, tint[f], geometry::Vec2{1, 2});
      for (std::uint32_t k = 0; k < 3; ++k) mesh_.indices.push_back(base + k);
    }
    if (!config().texturing()) mesh_ = bake_texture(mesh_, img, 4);
    return {};
  }

  Result<void> frame(draw::Context& ctx, unsigned n) override {
    if (auto r = begin_frame(ctx, config(), {0.08, 0.08, 0.12, 1}); !r) return r;
    ctx.set_cull(geometry::CullMode::Back);
    const double t = n * 0.06;
    const auto model = geometry::rotate_y(0.7 + t * 1.3) * geometry::rotate_x(0.5 + t * 0.7);
    ctx.set_transform(projection(ctx, 0.9, 0.5, 20) * geometry::look_at({0, 0, 4.2}, {0, 0, 0}, {0, 1, 0}) * model);
    if (config().texturing()) {
      if (auto r = ctx.bind_texture(texture_); !r) return r;
    } else {
      ctx.unbind_texture();
    }
    return ctx.draw_indexed(mesh_.vertices, mesh_.indices);
  }

 private:
  draw::Texture texture_;
  Mesh mesh_;
};

}  // namespace

std::unique_ptr<Example> make_tetrahedron() { return std::make_unique<Tetrahedron>(); }

}  // namespace gpubridge::examples
