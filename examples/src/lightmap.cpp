// DMC-1's lightmap trick: a brick wall drawn, then drawn again with the same geometry, a
// lightmap texture, the EQUAL depth test and multiplicative blending. Identical vertices give
// identical snapped coordinates and depths, so the second pass touches exactly the first's pixels.
#include <cmath>

#include "examples_internal.hpp"
#include "mesh.hpp"

namespace gpubridge::examples {
namespace {

class Lightmap final : public Example {
 public:
  ExampleInfo info() const override {
    return {"lightmap", "DMC-1", "a brick wall lit by a lightmap in a second pass (EQUAL depth test, MULTIPLY blend)"};
  }

  Result<void> setup(draw::Context& ctx) override {
    wall_ = {};
    floor_ = {};
    auto b = ctx.create_texture(brick_texture(64), {});
    if (!b) return b.error();
    bricks_ = *b;
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
    auto l = ctx.create_texture(lm, {.bilinear = true});
    if (!l) return l.error();
    light_ = *l;
    // The wall: 4 x 2 quads, u, v in [0, 2] for both passes.
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 4; ++i) {
        const double x0 = -4 + 2 * i, x1 = x0 + 2, y0 = 2.0 * j, y1 = y0 + 2;
        wall_.quad({x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}, {1, 1, 1, 1}, {i * 0.5, 1 - j * 0.5 - 0.5},
                   {i * 0.5 + 0.5, 1 - j * 0.5});
      }
    for (auto& v : wall_.vertices) v.uv = {v.uv.x * 2, v.uv.y * 2};
    floor_.quad({-6, 0, 3}, {6, 0, 3}, {6, 0, -1}, {-6, 0, -1}, {0.35, 0.33, 0.3, 1});
    return {};
  }

  Result<void> frame(draw::Context& ctx, unsigned n) override {
    if (auto r = ctx.clear({0.05, 0.05, 0.07, 1}); !r) return r;
    if (auto r = ctx.clear_depth(1.0); !r) return r;
    const double sway = 0.35 * std::sin(n * 0.1);
    ctx.set_transform(projection(ctx, 0.9, 0.5, 40) *
                      geometry::look_at({3.0 + 2 * sway, 2.2, 6.5}, {0.3 * sway, 1.9, 0}, {0, 1, 0}));
    ctx.set_cull(geometry::CullMode::Back);
    // Pass 1: bricks (decal), writing depth.
    ctx.state() = {};
    ctx.state().z_test = ctx.state().z_write = true;
    ctx.unbind_texture();
    if (auto r = ctx.draw_indexed(floor_.vertices, floor_.indices); !r) return r;
    ctx.state().tex_decal = true;
    if (auto r = ctx.bind_texture(bricks_); !r) return r;
    if (auto r = ctx.draw_indexed(wall_.vertices, wall_.indices); !r) return r;
    // Pass 2: the lightmap where the depth is EQUAL, multiplied into the bricks.
    ctx.state().z_func = protocol::DepthFunc::Equal;
    ctx.state().z_write = false;
    ctx.state().blend = protocol::BlendMode::Multiply;
    if (auto r = ctx.bind_texture(light_); !r) return r;
    return ctx.draw_indexed(wall_.vertices, wall_.indices);
  }

 private:
  draw::Texture bricks_, light_;
  Mesh wall_, floor_;
};

}  // namespace

std::unique_ptr<Example> make_lightmap() { return std::make_unique<Lightmap>(); }

}  // namespace gpubridge::examples
