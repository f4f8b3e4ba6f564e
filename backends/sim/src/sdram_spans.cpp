#include "sdram_spans.hpp"

#include <algorithm>

#include "fixed_point.hpp"

namespace gpubridge::sim {

void access_triangle_rows(SdramRows& rows, const Triangle& t, const DrawState& st) {
  const int w = t.x1 - t.x0;
  if (w <= 0 || t.y1 <= t.y0) return;
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
    access_span(rows, span);
  }
}

}  // namespace gpubridge::sim
