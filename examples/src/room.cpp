// Foenix: a walk through a room whose partition wall the camera passes straight through; each
// triangle is clipped against the near plane right before rasterisation (0, 1 or 2 triangles).
#include <cmath>

#include "examples_internal.hpp"
#include "mesh.hpp"

namespace gpubridge::examples {
namespace {

constexpr double kHalf = 6, kHeight = 3;

class Room final : public Example {
 public:
  ExampleInfo info() const override {
    return {"room", "Foenix A2560", "a walk through a room and straight through a wall, clipped at the near plane"};
  }

  Result<void> setup(draw::Context& ctx) override {
    floor_ = {};
    ceiling_ = {};
    walls_ = {};
    auto bricks = ctx.create_texture(brick_texture(64), {});
    if (!bricks) return bricks.error();
    bricks_ = *bricks;
    auto floor = ctx.create_texture(checker_texture(32, 2, {0.85, 0.82, 0.75, 1}, {0.35, 0.3, 0.28, 1}), {});
    if (!floor) return floor.error();
    floor_tex_ = *floor;
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
    return {};
  }

  Result<void> frame(draw::Context& ctx, unsigned n) override {
    if (auto r = ctx.clear({0, 0, 0, 1}); !r) return r;
    if (auto r = ctx.clear_depth(1.0); !r) return r;
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
    ctx.state() = {};
    ctx.state().z_test = ctx.state().z_write = true;
    ctx.set_cull(geometry::CullMode::Back);
    if (auto r = ctx.bind_texture(floor_tex_); !r) return r;
    if (auto r = ctx.draw_indexed(floor_.vertices, floor_.indices); !r) return r;
    if (auto r = ctx.bind_texture(bricks_); !r) return r;
    if (auto r = ctx.draw_indexed(walls_.vertices, walls_.indices); !r) return r;
    ctx.unbind_texture();
    return ctx.draw_indexed(ceiling_.vertices, ceiling_.indices);
  }

 private:
  draw::Texture bricks_, floor_tex_;
  Mesh floor_, ceiling_, walls_;
};

}  // namespace

std::unique_ptr<Example> make_room() { return std::make_unique<Room>(); }

}  // namespace gpubridge::examples
