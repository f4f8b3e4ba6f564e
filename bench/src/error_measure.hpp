#pragma once
// Error of a rendered frame against the double-precision reference (internal to the bench).
#include <cstdint>
#include <span>
#include <vector>

#include "gpubridge/accuracy/reference.hpp"
#include "gpubridge/bench/accuracy_bench.hpp"
#include "gpubridge/bench/scenes.hpp"

namespace gpubridge::bench {

// What the reference says about every pixel after drawing a scene's error subset in order with
// depth ALWAYS and no blending: how many triangles cover it, which one covered it last (its
// owner), and the owner's exact attribute values.
struct ReferenceFrame {
  unsigned width = 0, height = 0;
  std::vector<std::uint32_t> count;
  std::vector<std::int64_t> owner;   // -1: not covered
  std::vector<double> z;             // 24-bit LSB
  std::vector<std::array<double, 4>> rgba;  // 8-bit LSB
  std::vector<double> u_texels, v_texels;   // u * W, v * H of the probe texture
};
ReferenceFrame reference_frame(const Scene& scene);

// What a renderer produced for the same draw: hit counts and owners (owners may be unknown, then
// the reference owner is assumed wherever the counts agree), RGBA8 colour and 24-bit depth,
// optionally texel coordinates measured directly (llvmpipe's float target) instead of the probe.
struct RenderedFrame {
  std::vector<std::uint32_t> count;
  std::vector<std::int64_t> owner;  // empty: unknown
  std::vector<std::uint8_t> rgba;   // width * height * 4
  std::vector<std::uint32_t> depth;
  std::vector<float> texel_coordinates;  // width * height * 4 (u*W, v*H, -, -); empty: use the probe colour
};
ErrorStats measure_error(const Scene& scene, const ReferenceFrame& ref, const RenderedFrame& got);

// Device-register triangle back to floats for llvmpipe (the same numbers the reference uses).
struct GlVertex;
void to_gl(const geometry::DeviceTriangle& t, GlVertex out[3]);

}  // namespace gpubridge::bench
