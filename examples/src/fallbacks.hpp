#pragma once
// What the examples draw instead of a feature the device lacks (fit.hpp):
//  - painter's order instead of a depth buffer: triangles drawn far to near;
//  - a texture baked into vertex colours instead of the texture unit: each triangle cut into
//    smaller ones whose corners carry the texture's colour there (Gouraud shading does the rest).
#include <cstdint>
#include <span>
#include <vector>

#include "gpubridge/common/image.hpp"
#include "gpubridge/geometry/math.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "mesh.hpp"

namespace gpubridge::examples {

// `indices` (3 per triangle) reordered so that triangles with a larger distance come first.
// distance[t] belongs to triangle t; equal distances keep their order (deterministic).
std::vector<std::uint32_t> far_to_near(std::span<const std::uint32_t> indices, std::span<const double> distance);

// The view depth (clip-space w under `mvp`) of each triangle's centroid: a painter's key that is
// exact for triangles that do not overlap in depth, an approximation otherwise.
std::vector<double> centroid_depths(std::span<const draw::Vertex> vertices, std::span<const std::uint32_t> indices,
                                    const geometry::Mat4& mvp);

// The mesh with `texture` baked in: every triangle cut into n x n (n >= 1), each corner's colour
// its interpolated colour times the texture there (decal: the texture's colour), averaged over
// the texels a small triangle covers (so patterns finer than the mesh turn into their mean
// instead of aliasing). UVs are kept; the result draws untextured.
Mesh bake_texture(const Mesh& mesh, const Image& texture, unsigned n, bool decal = false,
                  protocol::Wrap wrap_s = protocol::Wrap::Repeat, protocol::Wrap wrap_t = protocol::Wrap::Repeat);

}  // namespace gpubridge::examples
