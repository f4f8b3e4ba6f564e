#pragma once
// Factories of the individual examples and small helpers they share.
#include <memory>

#include "gpubridge/examples/example.hpp"
#include "gpubridge/examples/torus.hpp"
#include "gpubridge/geometry/math.hpp"

namespace gpubridge::examples {

std::unique_ptr<Example> make_tetrahedron();
std::unique_ptr<Example> make_terrain();
std::unique_ptr<Example> make_voxels();
std::unique_ptr<Example> make_room();
std::unique_ptr<Example> make_cubes();
std::unique_ptr<Example> make_lightmap();

// The start of every frame: the colour buffer cleared; with a depth buffer, depth cleared and
// tested and written by the following draws (without one the example draws in painter's order);
// TRI_MODE.DITHER as the configuration says; every other state at its default.
Result<void> begin_frame(draw::Context& ctx, const Fit& fit, geometry::Vec4 clear_color);

// Perspective projection with the context's aspect ratio.
inline geometry::Mat4 projection(const draw::Context& ctx, double fovy, double near_z, double far_z) {
  return geometry::perspective(fovy, static_cast<double>(ctx.width()) / ctx.height(), near_z, far_z);
}

}  // namespace gpubridge::examples
