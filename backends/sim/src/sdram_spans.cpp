#include "sdram_spans.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

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

namespace {

// A wrapped texel index (section 10.3) of a texture 2^log2 texels wide.
unsigned wrap_index(std::int64_t i, unsigned log2, protocol::Wrap mode) {
  const std::int64_t n = std::int64_t{1} << log2;
  switch (mode) {
    case protocol::Wrap::Clamp: return static_cast<unsigned>(std::clamp<std::int64_t>(i, 0, n - 1));
    case protocol::Wrap::Mirror: {
      const std::int64_t k = i & (2 * n - 1);
      return static_cast<unsigned>(k < n ? k : 2 * n - 1 - k);
    }
    default: return static_cast<unsigned>(i & (n - 1));
  }
}

// What the texel cache keeps a draw's texels across: texture, its format and the buffers.
std::uint64_t texture_signature(const DrawState& st) {
  std::uint64_t h = st.tex.base;
  for (std::uint64_t v : {std::uint64_t(st.tex.wl), std::uint64_t(st.tex.hl), std::uint64_t(st.tex.format),
                          std::uint64_t(st.tex.bilinear), std::uint64_t(st.tex.wrap_s), std::uint64_t(st.tex.wrap_t),
                          std::uint64_t(st.fb_draw), std::uint64_t(st.fb_z), std::uint64_t(st.fb_format)})
    h = (h ^ v) * 0x100000001B3ull;
  return h;
}

// One covered span of a textured triangle, pixel by pixel: its depth accesses, the texel reads
// its samples miss in the cache, and its colour word after the word's last pixel.
class TexturedSpans {
 public:
  TexturedSpans(SdramRows& rows, TexelCache& texels, const Triangle& t, const DrawState& st)
      : out_(rows), texels_(texels), t_(t), st_(st) {
    texels_.begin(texture_signature(st));
    texel_bytes_ = protocol::bytes_per_pixel(st.tex.format);
    // s, t, q times 2D along a row: the edge values' steps per column weigh the vertices
    for (int i = 0; i < 3; ++i) {
      const double ex = double(t.edge[i].ex);
      ds_ += ex * double(t.v[i].s);
      dt_ += ex * double(t.v[i].t);
      dq_ += ex * double(t.v[i].q);
    }
  }
  void span(const SpanAccess& s, std::int64_t k, std::int64_t kl) {
    const std::uint64_t zn = (s.z_read ? 1u : 0u) + (s.z_write ? 1u : 0u);
    const std::uint64_t cn = (s.color_read ? 1u : 0u) + (s.color_write ? 1u : 0u);
    // s, t, q times 2D at column 0 of row k (the edge values are the vertices' weights)
    s0_ = t0_ = q0_ = 0;
    for (int i = 0; i < 3; ++i) {
      const double e = double(t_.edge[i].e + k * t_.edge[i].ey);
      s0_ += e * double(t_.v[i].s);
      t0_ += e * double(t_.v[i].t);
      q0_ += e * double(t_.v[i].q);
    }
    for (std::uint64_t p = 0; p < s.pixels; ++p) {
      out_.emit(s.depth + 4 * p, zn);
      sample(double(kl + static_cast<std::int64_t>(p)));
      const std::uint64_t c = s.color + s.bpp * p;
      // the combiner sends the word after its last pixel of the span
      if (p + 1 == s.pixels || ((c + s.bpp) >> 2) != (c >> 2)) out_.emit(c & ~std::uint64_t{3}, cn);
    }
  }

 private:
  // The pixel at column kx of the span's row: its texel indices, each looked up.
  void sample(double kx) {
    const double es = s0_ + kx * ds_, et = t0_ + kx * dt_, eq = q0_ + kx * dq_;
    // u = S / Q in texture widths (S = s / 2^24, Q = q / 2^32), in texels; q = 0: texel 0
    const double r = eq > 0 ? 256.0 / eq : 0.0;
    const double u = es * r * double(1u << st_.tex.wl), v = et * r * double(1u << st_.tex.hl);
    const bool bi = st_.tex.bilinear;
    const auto i0 = static_cast<std::int64_t>(std::floor(bi ? u - 0.5 : u));
    const auto j0 = static_cast<std::int64_t>(std::floor(bi ? v - 0.5 : v));
    for (int n = 0; n < (bi ? 4 : 1); ++n) {
      const unsigned i = wrap_index(i0 + (n & 1), st_.tex.wl, st_.tex.wrap_s);
      const unsigned j = wrap_index(j0 + (n >> 1), st_.tex.hl, st_.tex.wrap_t);
      if (texels_.lookup(i, j)) continue;
      const std::uint64_t at = st_.tex.base + ((std::uint64_t{j} << st_.tex.wl) + i) * texel_bytes_;
      out_.emit(at & ~std::uint64_t{3}, 1);
    }
  }

  RowRunEmitter out_;
  TexelCache& texels_;
  const Triangle& t_;
  const DrawState& st_;
  std::uint64_t texel_bytes_ = 4;
  double ds_ = 0, dt_ = 0, dq_ = 0;  // per column
  double s0_ = 0, t0_ = 0, q0_ = 0;  // at the row's column 0
};

}  // namespace

std::uint64_t access_triangle_rows(SdramRows& rows, TexelCache& texels, const Triangle& t, const DrawState& st) {
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
  rows.set_textured(st.mode_class & 4);
  std::optional<TexturedSpans> textured;
  if (st.mode_class & 4) textured.emplace(rows, texels, t, st);
  else texels.invalidate();  // another draw: the core forgets its texels
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
    if (textured) textured->span(span, k, kl);
    else access_span(rows, span);
  }
  return covered;
}

}  // namespace gpubridge::sim
