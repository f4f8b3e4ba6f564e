// DMC-1's lightmap trick: a brick wall drawn, then drawn again with the same geometry, a
// lightmap texture, the EQUAL depth test and multiplicative blending. Identical vertices give
// identical snapped coordinates and depths, so the second pass touches exactly the first's pixels.
#include <cmath>

#include "examples_internal.hpp"
#include "fallbacks.hpp"
#include "mesh.hpp"

namespace gpubridge::examples {
namespace {

class Lightmap final : public Example {
 public:
  ExampleInfo info() const override {
    return {"lightmap", "DMC-1", "a brick wall lit by a lightmap in a second pass (EQUAL depth test, MULTIPLY blend)"};
  }

  Wants wants(std::uint16_t features) const override {
    Wants w;
    w.textures = {{"bricks", 64, 64, protocol::PixelFormat::RGBA8888}};
    if (features & kBlend) {
      w.textures.push_back({"lightmap", 32, 32, protocol::PixelFormat::RGBA8888, true});
      // The second pass over the same geometry with EQUAL depth is the idea: the depth buffer
      // is held longest, before the size.
      w.keep = {Knob::Depth, Knob::Size, Knob::Format, Knob::Textures, Knob::DoubleBuffer};
      w.without_depth = "the lightmap pass without a depth test (the same triangles cover the same pixels, and "
                        "nothing covers the wall)";
    } else {
      w.without_depth = "the floor, then the wall (nothing covers the wall)";
    }
    w.without_feature = {{kBlend, "the lightmap baked into the wall's vertex colours, one pass"},
                         {kBilinear, "the lightmap sampled nearest"},
                         {kTexturing, "bricks and lightmap baked into the wall's vertex colours"}};
    return w;
  }

  Result<void> setup(draw::Context& ctx) override {
    wall_ = {};
    floor_ = {};
    light_wall_ = {};
    bricks_ = light_ = {};
    const Image bricks = brick_texture(64);
    // 32x32 lightmap: two warm light pools and a cool one, tiled 2x2 over the wall like the bricks.
    Image lm = make_image(32, 32);
    for (unsigned y = 0; y < 32; ++y)
      for (unsigned x = 0; x < 32; ++x) {
        auto pool = [&](double cx, double cy, double r) {
          const double dx = std::min(std::fabs(x + 0.5 - cx), 32 - std::fabs(x + 0.5 - cx));
          const double dy = std::min(std::fabs(y + 0.5 - cy), 32 - std::fabs(y + 0.5 - cy));
          return std::exp(-(dx * dx + dy * dy) / (r * r));
        };
        const double warm = pool(8, 10, 7), cool = pool(24, 22, 6);
        put(lm, x, y, 0.18 + 0.9 * warm + 0.3 * cool, 0.16 + 0.75 * warm + 0.5 * cool, 0.2 + 0.35 * warm + 0.9 * cool);
      }
    const bool blend = config().has(kBlend), textured = config().texturing();
    if (textured) {
      auto b = ctx.create_texture(config().texture(0).shrink(bricks), config().texture(0).options());
      if (!b) return b.error();
      bricks_ = *b;
      if (blend) {
        auto l = ctx.create_texture(config().texture(1).shrink(lm), config().texture(1).options());
        if (!l) return l.error();
        light_ = *l;
      }
    }
    // The wall: 4 x 2 quads, u, v in [0, 2] for both passes.
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 4; ++i) {
        const double x0 = -4 + 2 * i, x1 = x0 + 2, y0 = 2.0 * j, y1 = y0 + 2;
        wall_.quad({x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}, {1, 1, 1, 1}, {i * 0.5, 1 - j * 0.5 - 0.5},
                   {i * 0.5 + 0.5, 1 - j * 0.5});
      }
    for (auto& v : wall_.vertices) v.uv = {v.uv.x * 2, v.uv.y * 2};
    floor_.quad({-6, 0, 3}, {6, 0, 3}, {6, 0, -1}, {-6, 0, -1}, {0.35, 0.33, 0.3, 1});
    // Without blending the lightmap goes into the wall's vertex colours (cut finely enough for
    // its light pools) and the bricks, textured, are modulated by them in one pass. Without a
    // texture unit both passes draw baked walls; cut alike, they still cover identical pixels.
    if (!blend) {
      light_wall_ = bake_texture(wall_, lm, 8);
      if (!textured) light_wall_ = bake_texture(light_wall_, bricks, 1);
    } else if (!textured) {
      light_wall_ = bake_texture(wall_, lm, 8, true);
      wall_ = bake_texture(wall_, bricks, 8, true);
    }
    return {};
  }

  Result<void> frame(draw::Context& ctx, unsigned n) override {
    if (auto r = begin_frame(ctx, config(), {0.05, 0.05, 0.07, 1}); !r) return r;
    const double sway = 0.35 * std::sin(n * 0.1);
    ctx.set_transform(projection(ctx, 0.9, 0.5, 40) *
                      geometry::look_at({3.0 + 2 * sway, 2.2, 6.5}, {0.3 * sway, 1.9, 0}, {0, 1, 0}));
    ctx.set_cull(geometry::CullMode::Back);
    // The floor first: in painter's order it cannot cover the wall, which stands on it.
    ctx.unbind_texture();
    if (auto r = ctx.draw_indexed(floor_.vertices, floor_.indices); !r) return r;
    const bool textured = config().texturing();
    if (!config().has(kBlend)) {
      // One pass: the bricks modulated by the baked lightmap.
      if (textured)
        if (auto r = ctx.bind_texture(bricks_); !r) return r;
      return ctx.draw_indexed(light_wall_.vertices, light_wall_.indices);
    }
    // Pass 1: bricks (decal), writing depth.
    ctx.state().tex_decal = true;
    if (textured)
      if (auto r = ctx.bind_texture(bricks_); !r) return r;
    if (auto r = ctx.draw_indexed(wall_.vertices, wall_.indices); !r) return r;
    // Pass 2: the lightmap where the depth is EQUAL, multiplied into the bricks.
    if (!config().painter()) {
      ctx.state().z_func = protocol::DepthFunc::Equal;
      ctx.state().z_write = false;
    }
    ctx.state().blend = protocol::BlendMode::Multiply;
    if (!textured) return ctx.draw_indexed(light_wall_.vertices, light_wall_.indices);
    if (auto r = ctx.bind_texture(light_); !r) return r;
    return ctx.draw_indexed(wall_.vertices, wall_.indices);
  }

 private:
  draw::Texture bricks_, light_;
  Mesh wall_, floor_, light_wall_;  // light_wall_: the lightmap baked in, when a feature is missing
};

}  // namespace

std::unique_ptr<Example> make_lightmap() { return std::make_unique<Lightmap>(); }

}  // namespace gpubridge::examples
