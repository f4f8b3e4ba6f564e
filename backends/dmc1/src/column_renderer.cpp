#include "column_renderer.hpp"

#include <algorithm>

#include "fixed_point.hpp"

namespace gpubridge::dmc1 {

// One worker's rows [lo, hi] of every column in the batch.
struct ColumnRenderer::Band {
  const std::uint8_t* memory;  // the 16 MiB texture address space
  ColumnBuffers& buffers;
  unsigned lo, hi;
  std::uint16_t* column = nullptr;  // the draw buffer's entries
  std::uint32_t tag = 0;            // the draw buffer in bit 31 (depth buffer tag)

  std::uint8_t texel(const TextureBinding& b, std::uint32_t u, std::uint32_t v) const {
    u &= (1u << b.wp2) - 1;
    v &= (1u << b.hp2) - 1;
    return memory[(b.base + (u | (v << b.wp2))) & TextureMemory::kAddressMask];
  }

  // The write stage: normal mode stores {L4 << 4, texel}; lightmap mode only the light byte.
  // Every written pixel also writes its depth. Branch-free: whether a pixel lands depends on
  // texels and depths the branch predictor cannot guess.
  void write(unsigned row, bool lightmap, bool opaque, std::uint16_t entry, std::uint32_t dist) {
    std::uint32_t& d = buffers.depth[row];
    std::uint16_t& e = column[row];
    const bool ok = opaque && depth_passes(d, dist, tag);
    const std::uint16_t value = lightmap ? static_cast<std::uint16_t>((e & 0xFF) | entry << 8) : entry;
    e = ok ? value : e;
    d = ok ? (tag | dist) : d;
  }

  // Rows of the job inside this band, as pixel indices j (row = start + j); false when none.
  bool rows(const SpanJob& job, unsigned& j0, unsigned& j1) const {
    const unsigned a = std::max<unsigned>(job.start, lo), b = std::min<unsigned>(job.end, hi);
    if (a > b) return false;
    j0 = a - job.start;
    j1 = b - job.start;
    return true;
  }

  void fill(const SpanJob& job) {
    unsigned j0, j1;
    if (!rows(job, j0, j1)) return;
    for (unsigned j = j0; j <= j1; ++j) write(job.start + j, job.lightmap, true, job.entry, job.dist);
  }

  // Wall: constant u, depth and light; v advances by v_step (11 fractional bits) per row. The
  // texels are gathered first: independent loads overlap their cache misses, which a loop that
  // tests each texel before the next load serialises.
  void wall(const SpanJob& job) {
    unsigned j0, j1;
    if (!rows(job, j0, j1)) return;
    std::uint8_t texels[kRows];
    std::uint32_t v = job.v_fixed + j0 * job.v_step;
    for (unsigned j = j0; j <= j1; ++j, v += job.v_step) texels[j - j0] = texel(job.binding, job.u, (v >> 11) & 255);
    const unsigned l4 = light_nibble(job.light, job.dist);
    for (unsigned j = j0; j <= j1; ++j) {
      const std::uint8_t t = texels[j - j0];
      write(job.start + j, job.lightmap, t != kTransparentTexel || job.lightmap,
            job.lightmap ? t : static_cast<std::uint16_t>(l4 << 12 | t), job.dist);
    }
  }

  // Plane: pixel j's texel uses dot_u/dot_v after j row events and dot_ray after max(j - 1, 0);
  // its depth uses dot_ray after j + 1 (the RTL reads the 1/n table one cycle late and keeps the
  // previous ray_t in the register the depth test reads). Texels are gathered first, as for walls.
  void plane(const SpanJob& job) {
    unsigned j0, j1;
    if (!rows(job, j0, j1)) return;
    const unsigned shift = job.lightmap ? 14 : 10;  // lightmaps: one texel per 16 texture texels
    std::uint8_t texels[kRows];
    std::uint32_t dists[kRows];
    std::int32_t dr = wrap24(job.dot_ray + std::int64_t{job.ny} * j0);
    std::int32_t du = wrap24(job.dot_u + std::int64_t{job.uy} * j0);
    std::int32_t dv = wrap24(job.dot_v + std::int64_t{job.vy} * j0);
    for (unsigned j = j0; j <= j1; ++j) {
      const std::int32_t t_texel = plane_ray_t(j == 0 ? dr : wrap24(std::int64_t{dr} - job.ny), job.ded);
      const std::int32_t t_depth = plane_ray_t(wrap24(std::int64_t{dr} + job.ny), job.ded);
      const auto u = static_cast<std::uint32_t>(plane_coordinate(t_texel, du, job.u_offset) >> shift) & 255;
      const auto v = static_cast<std::uint32_t>(plane_coordinate(t_texel, dv, job.v_offset) >> shift) & 255;
      dr = wrap24(std::int64_t{dr} + job.ny);
      du = wrap24(std::int64_t{du} + job.uy);
      dv = wrap24(std::int64_t{dv} + job.vy);
      texels[j - j0] = job.background ? kBackgroundTexel : texel(job.binding, u, v);
      dists[j - j0] = static_cast<std::uint32_t>(t_depth) << 1 & 0x7FFFFFFF;
    }
    for (unsigned j = j0; j <= j1; ++j) {
      const std::uint8_t t = texels[j - j0];
      const std::uint32_t dist = dists[j - j0];
      const unsigned l4 = job.background ? 15 : light_nibble(job.light, dist);
      write(job.start + j, job.lightmap, t != kTransparentTexel || job.lightmap,
            job.lightmap ? t : static_cast<std::uint16_t>(l4 << 12 | t), dist);
    }
  }

  void pixels(const SpanJob& job, const PixelWrite* writes) {
    for (std::uint32_t i = 0; i < job.writes; ++i) {
      const PixelWrite& w = writes[job.first_write + i];
      if (w.row >= lo && w.row <= hi) write(w.row, job.lightmap, true, w.entry, w.dist);
    }
  }
};

ColumnRenderer::ColumnRenderer(std::shared_ptr<const TextureMemory> textures, unsigned threads)
    : textures_(std::move(textures)), pool_(std::clamp(threads, 1u, kRows)) {}

void ColumnRenderer::run(const CommandFifo& fifo, ColumnBuffers& buffers, const Scanout& scanout, std::uint16_t* screen) {
  const unsigned workers = pool_.workers();
  const std::function<void(unsigned)> job = [&](unsigned w) {
    Band band{textures_->data(), buffers, kRows * w / workers, kRows * (w + 1) / workers - 1};
    unsigned buffer = fifo.first_buffer;
    band.column = buffers.entries[buffer].data();
    band.tag = buffer << 31;
    for (const SpanJob& s : fifo.jobs) {
      switch (s.type) {
        case JobType::Fill: band.fill(s); break;
        case JobType::Wall: band.wall(s); break;
        case JobType::Plane: band.plane(s); break;
        case JobType::Pixels: band.pixels(s, fifo.writes.data()); break;
        case JobType::EndOfColumn:
          scanout.column(band.column + band.lo, screen + std::size_t{s.column} * kRows + band.lo, band.hi - band.lo + 1);
          buffer ^= 1;
          band.column = buffers.entries[buffer].data();
          band.tag = buffer << 31;
          break;
      }
    }
  };
  pool_.start(job);
  pool_.wait();
}

}  // namespace gpubridge::dmc1
