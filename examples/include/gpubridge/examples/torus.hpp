#pragma once
// The donut ASIC example (seed 003) and its variants: a torus lit per vertex on the host and
// dithered to RGBA2222. Two ideas of the seed are selectable:
//  - temporal dither: TRI_MODE.TEMPORAL with DITHER_PHASE = frame number (docs/protocol.md 11.1);
//  - shift-and-add arithmetic: the model rotation and the lighting dot products computed with
//    CORDIC rotations (cordic.hpp) instead of floating-point matrices, iterations 4..16.
// TorusGeometry is the per-frame host work on its own, for `gpubridge bench accuracy`'s CORDIC front.
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "gpubridge/draw/context.hpp"
#include "gpubridge/examples/cordic.hpp"
#include "gpubridge/examples/example.hpp"

namespace gpubridge::examples {

struct TorusOptions {
  bool temporal = false;           // temporal dither instead of the ordered dither
  unsigned cordic_iterations = 0;  // 0: floating point; 4..16: shift-and-add rotations
  bool rgba8888 = false;           // RGBA8888 without dither (error measurements and reference figures)
  std::optional<unsigned> pose = std::nullopt;  // draw this frame's pose in every frame (only the dither phase moves)
};

// The mesh and the per-frame vertex stage: rotation of the positions and lighting.
class TorusGeometry {
 public:
  explicit TorusGeometry(unsigned cordic_iterations = 0);  // 0 = floating point

  // Frame n's vertices with their lit colours, and the model matrix the draw must apply: the
  // floating-point path returns model-space positions and the rotation as a matrix (folded into
  // the transform the draw applies anyway); the CORDIC path rotates the positions itself and
  // returns the identity.
  struct Frame {
    std::vector<draw::Vertex> vertices;
    geometry::Mat4 model = geometry::identity();
  };
  void frame(unsigned n, Frame& out) const;

  const std::vector<std::uint32_t>& indices() const { return indices_; }
  unsigned cordic_iterations() const { return iterations_; }
  // Camera: view matrix, vertical field of view and clip planes.
  static geometry::Mat4 view();
  static constexpr double kFovY = 0.8, kNear = 0.5, kFar = 20;

 private:
  void frame_float(unsigned n, Frame& out) const;
  void frame_cordic(unsigned n, Frame& out) const;

  unsigned iterations_ = 0;
  std::vector<geometry::Vec3> positions_, normals_;
  std::vector<std::uint32_t> indices_;
  // CORDIC path: positions in fixed point divided by K(n)^2 (two rotations each), the light and
  // highlight directions divided by K(n)^4 (two per frame, two per vertex), mesh angles.
  std::vector<cordic::Vec2> pos_xy_;
  std::vector<std::int32_t> pos_z_;
  std::vector<cordic::Angle> ring_angle_, tube_angle_;  // per ring i and per tube step j
  std::int32_t light_[3] = {}, highlight_[3] = {};
};

std::unique_ptr<Example> make_torus(const TorusOptions& options = {});

}  // namespace gpubridge::examples
