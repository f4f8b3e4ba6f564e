// Error measurement against the reference (see error_measure.hpp).
#include "error_measure.hpp"

#include <algorithm>
#include <cmath>

#include "gpubridge/accuracy/from_device.hpp"
#include "gpubridge/accuracy/texel_probe.hpp"
#include "gpubridge/bench/llvmpipe_peer.hpp"

namespace gpubridge::bench {

namespace {
constexpr double kTextureSize = double(1u << kTextureLog2);
}  // namespace

ReferenceFrame reference_frame(const Scene& scene) {
  ReferenceFrame r;
  r.width = scene.width;
  r.height = scene.height;
  const std::size_t n = std::size_t{scene.width} * scene.height;
  r.count.assign(n, 0);
  r.owner.assign(n, -1);
  r.z.assign(n, 0);
  r.rgba.assign(n, {});
  r.u_texels.assign(n, 0);
  r.v_texels.assign(n, 0);
  const accuracy::PixelRect clip{0, 0, int(scene.width), int(scene.height)};
  for (std::size_t k = 0; k < scene.error_subset && k < scene.triangles.size(); ++k) {
    for (const auto& s : accuracy::rasterize(accuracy::to_fixed(scene.triangles[k]), clip)) {
      const std::size_t i = std::size_t(s.y) * scene.width + std::size_t(s.x);
      r.count[i] += 1;
      r.owner[i] = std::int64_t(k);
      r.z[i] = s.z;
      r.rgba[i] = s.rgba;
      r.u_texels[i] = s.u() * kTextureSize;
      r.v_texels[i] = s.v() * kTextureSize;
    }
  }
  return r;
}

ErrorStats measure_error(const Scene& scene, const ReferenceFrame& ref, const RenderedFrame& got) {
  ErrorStats e;
  e.has_color = !scene.textured;
  e.has_texel = scene.textured;
  double color_sum = 0, texel_sum = 0;
  std::uint64_t judged = 0;
  for (std::size_t i = 0; i < ref.count.size(); ++i) {
    if (ref.count[i] == 0 && got.count[i] == 0) continue;
    e.pixels += ref.count[i] > 0;
    const bool owner_ok = got.owner.empty() || got.owner[i] == ref.owner[i];
    if (got.count[i] != ref.count[i] || !owner_ok) {
      ++e.coverage_mismatches;
      continue;
    }
    ++judged;
    e.z_max = std::max(e.z_max, std::fabs(double(got.depth[i]) - ref.z[i]));
    const std::uint8_t* c = &got.rgba[i * 4];
    if (e.has_color) {
      for (int ch = 0; ch < 4; ++ch) {
        const double d = std::fabs(double(c[ch]) - ref.rgba[i][ch]);
        e.color_max = std::max(e.color_max, d);
        color_sum += d;
      }
    }
    if (e.has_texel) {
      double du, dv;
      if (!got.texel_coordinates.empty()) {
        du = std::fabs(double(got.texel_coordinates[i * 4]) - ref.u_texels[i]);
        dv = std::fabs(double(got.texel_coordinates[i * 4 + 1]) - ref.v_texels[i]);
      } else {
        const auto ru = accuracy::read_probe_axis(c[0], c[1], ref.u_texels[i], 1u << kTextureLog2);
        const auto rv = accuracy::read_probe_axis(c[2], c[3], ref.v_texels[i], 1u << kTextureLog2);
        du = std::fabs(ru.position - ref.u_texels[i]);
        dv = std::fabs(rv.position - ref.v_texels[i]);
      }
      const double d = std::max(du, dv) * 256.0;
      e.texel_max = std::max(e.texel_max, d);
      texel_sum += d;
    }
  }
  if (judged > 0) {
    e.color_mean = color_sum / double(judged * 4);
    e.texel_mean = texel_sum / double(judged);
  }
  return e;
}

void to_gl(const geometry::DeviceTriangle& t, GlVertex out[3]) {
  for (int i = 0; i < 3; ++i) {
    const auto& v = t[i];
    GlVertex g;
    g.x = float(v.x) / 16.0f;
    g.y = float(v.y) / 16.0f;
    g.z = float(double(v.z & 0xFFFFFFu) / 16777215.0);
    const double q = v.q == 0 ? 1.0 : double(v.q);
    g.w = float(4294967296.0 / q);
    g.r = float((v.rgba >> 24) & 255) / 255.0f;
    g.g = float((v.rgba >> 16) & 255) / 255.0f;
    g.b = float((v.rgba >> 8) & 255) / 255.0f;
    g.a = float(v.rgba & 255) / 255.0f;
    g.u = float(256.0 * double(v.s) / q);
    g.v = float(256.0 * double(v.t) / q);
    out[i] = g;
  }
}

}  // namespace gpubridge::bench
