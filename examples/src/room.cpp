// Foenix: a walk through a room whose partition wall the camera passes straight through; each
// triangle is clipped against the near plane right before rasterisation (0, 1 or 2 triangles).
#include <cmath>

#include "examples_internal.hpp"
#include "fallbacks.hpp"
#include "mesh.hpp"

namespace gpubridge::examples {
namespace {

constexpr double kHalf = 6, kHeight = 3;

class Room final : public Example {
 public:
  ExampleInfo info() const override {
    return {"room", "Foenix A2560", "a walk through a room and straight through a wall, clipped at the near plane"};
  }

  Wants wants(std::uint16_t) const override {
    Wants w;
    w.textures = {{"bricks", 64, 64, protocol::PixelFormat::RGBA8888}, {"floor", 32, 32, protocol::PixelFormat::RGBA8888}};
    w.without_depth = "floor, ceiling, outer walls, then the partition (exact in this room)";
    w.without_feature = {{kTexturing, "bricks and floor tiles baked into the vertex colours"}};
    return w;
  }

  Result<void> setup(draw::Context& ctx) override {
    floor_ = {};
    ceiling_ = {};
    walls_ = {};
    bricks_ = floor_tex_ = {};
    const Image bricks = brick_texture(64);
    const Image tiles = checker_texture(32, 2, {0.85, 0.82, 0.75, 1}, {0.35, 0.3, 0.28, 1});
    if (config().texturing()) {
      auto b = ctx.create_texture(config().texture(0).shrink(bricks), config().texture(0).options());
      if (!b) return b.error();
      bricks_ = *b;
      auto f = ctx.create_texture(config().texture(1).shrink(tiles), config().texture(1).options());
      if (!f) return f.error();
      floor_tex_ = *f;
    }
    using V = geometry::Vec3;
    const geometry::Vec4 white{1, 1, 1, 1};
    // Floor (facing up) and ceiling (facing down), inside the room.
    floor_.quad(V{-kHalf, 0, kHalf}, V{kHalf, 0, kHalf}, V{kHalf, 0, -kHalf}, V{-kHalf, 0, -kHalf}, white, {0, 0}, {6, 6});
    ceiling_.quad(V{-kHalf, kHeight, -kHalf}, V{kHalf, kHeight, -kHalf}, V{kHalf, kHeight, kHalf}, V{-kHalf, kHeight, kHalf},
                  {0.55, 0.55, 0.6, 1});
    // Outer walls facing inwards, tinted per wall.
    walls_.quad(V{-kHalf, 0, -kHalf}, V{kHalf, 0, -kHalf}, V{kHalf, kHeight, -kHalf}, V{-kHalf, kHeight, -kHalf},
                {1, 1, 1, 1}, {0, 0}, {6, 1.5});
    walls_.quad(V{kHalf, 0, kHalf}, V{-kHalf, 0, kHalf}, V{-kHalf, kHeight, kHalf}, V{kHalf, kHeight, kHalf},
                {0.8, 0.8, 0.9, 1}, {0, 0}, {6, 1.5});
    walls_.quad(V{-kHalf, 0, kHalf}, V{-kHalf, 0, -kHalf}, V{-kHalf, kHeight, -kHalf}, V{-kHalf, kHeight, kHalf},
                {0.9, 0.85, 0.8, 1}, {0, 0}, {6, 1.5});
    walls_.quad(V{kHalf, 0, -kHalf}, V{kHalf, 0, kHalf}, V{kHalf, kHeight, kHalf}, V{kHalf, kHeight, -kHalf},
                {0.85, 0.9, 0.85, 1}, {0, 0}, {6, 1.5});
    // The partition at z = 0 from x = -6 to x = 2 (a doorway on the right), one quad per side.
    walls_.quad(V{-kHalf, 0, 0}, V{2, 0, 0}, V{2, kHeight, 0}, V{-kHalf, kHeight, 0}, {1, 0.9, 0.6, 1}, {0, 0}, {4, 1.5});
    walls_.quad(V{2, 0, 0}, V{-kHalf, 0, 0}, V{-kHalf, kHeight, 0}, V{2, kHeight, 0}, {0.6, 0.8, 1, 1}, {0, 0}, {4, 1.5});
    if (!config().texturing()) {
      // Cut finely enough for the floor's tiles (two vertices per tile) and a brick's height.
      floor_ = bake_texture(floor_, tiles, 24);
      walls_ = bake_texture(walls_, bricks, 12);
    }
    return {};
  }

  Result<void> frame(draw::Context& ctx, unsigned n) override {
    if (auto r = begin_frame(ctx, config(), {0, 0, 0, 1}); !r) return r;
    // Walk diagonally (49° off the wall's normal) and straight through the partition: at frame
    // 12 the eye is 0.03 in front of it, closer than the near plane (0.1), so the wall is cut
    // where it crosses the near plane and the far side of the room shows through. The walk
    // repeats every 48 frames.
    const double yaw = 0.85, step = 0.25;
    const double s = (static_cast<double>(n % 48) - 12.0) * step;
    const geometry::Vec3 dir{std::sin(yaw), 0, -std::cos(yaw)};
    const geometry::Vec3 eye = geometry::Vec3{-2, 1.6, 0.03} + dir * s;
    ctx.set_transform(projection(ctx, 1.1, 0.1, 30) *
                      geometry::look_at(eye, eye + dir + geometry::Vec3{0, -0.08, 0}, {0, 1, 0}));
    ctx.set_cull(geometry::CullMode::Back);
    // In painter's order the ceiling goes before the walls: from inside the room neither floor
    // nor ceiling can cover a wall, the outer walls (a convex box seen from inside) cannot cover
    // each other, and the partition, listed last, covers the rest.
    if (config().painter()) {
      if (auto r = draw_with(ctx, floor_tex_, floor_); !r) return r;
      if (auto r = draw_with(ctx, {}, ceiling_); !r) return r;
      return draw_with(ctx, bricks_, walls_);
    }
    if (auto r = draw_with(ctx, floor_tex_, floor_); !r) return r;
    if (auto r = draw_with(ctx, bricks_, walls_); !r) return r;
    return draw_with(ctx, {}, ceiling_);
  }

 private:
  // Draws the mesh with the texture bound, or untextured for an empty handle (the ceiling, or no
  // texture unit: the mesh is then baked).
  Result<void> draw_with(draw::Context& ctx, const draw::Texture& texture, const Mesh& m) {
    if (texture.id != 0) {
      if (auto r = ctx.bind_texture(texture); !r) return r;
    } else {
      ctx.unbind_texture();
    }
    return ctx.draw_indexed(m.vertices, m.indices);
  }

  draw::Texture bricks_, floor_tex_;
  Mesh floor_, ceiling_, walls_;
};

}  // namespace

std::unique_ptr<Example> make_room() { return std::make_unique<Room>(); }

}  // namespace gpubridge::examples
