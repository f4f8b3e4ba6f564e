#include "sdram_spans.hpp"

#include <algorithm>
#include <cmath>

#include "fixed_point.hpp"

namespace gpubridge::sim {

std::uint64_t texel_footprint_bytes(const Triangle& t, const DrawState& st, std::uint64_t covered) {
  const unsigned taps = st.tex.bilinear ? 4u : 1u;
  const std::uint64_t bytes = protocol::bytes_per_pixel(st.tex.format);
  const std::uint64_t samples = covered * taps * bytes;
  double u[3], v[3];
  for (int i = 0; i < 3; ++i) {
    if (t.v[i].q == 0) return samples;
    // u = S / Q in texture widths (S = s / 2^24, Q = q / 2^32), in texels
    u[i] = double(t.v[i].s) * 256.0 / double(t.v[i].q) * double(1u << st.tex.wl);
    v[i] = double(t.v[i].t) * 256.0 / double(t.v[i].q) * double(1u << st.tex.hl);
  }
  const double area = 0.5 * std::fabs((u[1] - u[0]) * (v[2] - v[0]) - (u[2] - u[0]) * (v[1] - v[0]));
  const double texels = st.tex.bilinear ? area + 2.0 * std::sqrt(area) + 1.0 : area + 1.0;
  const double capped = std::min(texels * double(bytes), double(samples));
  return static_cast<std::uint64_t>(std::llround(capped));
}

std::uint64_t access_triangle_rows(SdramRows& rows, const Triangle& t, const DrawState& st) {
  const int w = t.x1 - t.x0;
  std::uint64_t covered = 0;
  if (w <= 0 || t.y1 <= t.y0) return covered;
  const std::uint8_t stored = st.fb_format == protocol::PixelFormat::RGB565 ? 0x7 : 0xF;
  SpanAccess span;
  span.bpp = st.bpp;
  span.z_read = st.z_test;
  span.z_write = st.z_write;
  span.color_write = (st.keep_mask & stored) != stored;
  span.color_read = span.color_write && st.reads_color;
  for (int y = t.y0; y < t.y1; ++y) {
    const std::int64_t k = y - t.y0;
    std::int64_t kl = 0, kr = w - 1;
    for (const Edge& e : t.edge) {
      // covered where E + kx·ex >= 0 (the bias is in E)
      const std::int64_t ek = e.e + k * e.ey;
      if (e.ex > 0) kl = std::max(kl, -floor_div(ek, e.ex));
      else if (e.ex < 0) kr = std::min(kr, floor_div(ek, -e.ex));
      else if (ek < 0) kr = -1;
    }
    if (kl > kr) continue;
    const std::uint64_t pix = std::uint64_t(y) * st.fb_width + std::uint64_t(t.x0 + kl);
    span.color = st.fb_draw + pix * st.bpp;
    span.depth = st.fb_z + pix * 4;
    span.pixels = static_cast<unsigned>(kr - kl + 1);
    covered += span.pixels;
    access_span(rows, span);
  }
  return covered;
}

}  // namespace gpubridge::sim
