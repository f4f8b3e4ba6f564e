#include "column_renderer.hpp"

#include <algorithm>

#include "fixed_point.hpp"

namespace gpubridge::dmc1 {
namespace {

// The sampler's addressing for one bound texture, with its masks computed once per span.
struct Sampler {
  const std::uint8_t* memory;  // the 16 MiB texture address space
  std::uint32_t base, wmask, hmask, wp2;

  Sampler(const std::uint8_t* m, const TextureBinding& b)
      : memory(m), base(b.base), wmask((1u << b.wp2) - 1), hmask((1u << b.hp2) - 1), wp2(b.wp2) {}
  std::uint8_t operator()(std::uint32_t u, std::uint32_t v) const {
    return memory[(base + ((u & wmask) | ((v & hmask) << wp2))) & TextureMemory::kAddressMask];
  }
};

// The write stage for one row: normal mode stores the entry {L4 << 4, texel}; lightmap mode only
// its low byte, as the light byte; every written pixel also writes its depth. Masks instead of
// branches: whether a pixel lands depends on texels and depths no predictor can guess, and the
// loops below over __restrict arrays vectorise.
template <bool kLightmap>
inline void write_row(std::uint16_t& column, std::uint32_t& depth, std::uint32_t tag, std::uint16_t entry, std::uint32_t z,
                      bool opaque) {
  const std::uint32_t d = depth;
  const std::uint32_t m = 0u - static_cast<std::uint32_t>(depth_passes(d, z, tag) & opaque);
  depth = (d & ~m) | ((tag | z) & m);
  const std::uint16_t e = column;
  const auto value = kLightmap ? static_cast<std::uint16_t>((e & 0xFF) | entry << 8) : entry;
  column = static_cast<std::uint16_t>((e & ~m) | (value & m));
}

// n rows from arrays the span loops filled first (so the texel-gathering loops before it are free
// to overlap their loads).
template <bool kLightmap>
void write_rows(std::uint16_t* __restrict column, std::uint32_t* __restrict depth, std::uint32_t tag, unsigned n,
                const std::uint16_t* __restrict entry, const std::uint32_t* __restrict dist,
                const std::uint8_t* __restrict opaque) {
  for (unsigned i = 0; i < n; ++i) write_row<kLightmap>(column[i], depth[i], tag, entry[i], dist[i], opaque[i] != 0);
}

// n rows with one entry and depth (background fills, terrain writes).
template <bool kLightmap>
void fill_rows(std::uint16_t* __restrict column, std::uint32_t* __restrict depth, std::uint32_t tag, unsigned n,
               std::uint16_t entry, std::uint32_t z) {
  for (unsigned i = 0; i < n; ++i) write_row<kLightmap>(column[i], depth[i], tag, entry, z, true);
}

}  // namespace

// One worker's rows [lo, hi] of every column in the batch.
struct ColumnRenderer::Band {
  const std::uint8_t* memory;
  ColumnBuffers& buffers;
  unsigned lo, hi;
  std::uint16_t* column = nullptr;  // the draw buffer's entries
  std::uint32_t tag = 0;            // the draw buffer in bit 31 (depth buffer tag)

  // Rows of the job inside this band, as pixel indices j0..j1 (row = start + j); false when none.
  bool rows(const SpanJob& job, unsigned& j0, unsigned& j1) const {
    const unsigned a = std::max<unsigned>(job.start, lo), b = std::min<unsigned>(job.end, hi);
    if (a > b) return false;
    j0 = a - job.start;
    j1 = b - job.start;
    return true;
  }

  template <bool kLightmap>
  void fill(const SpanJob& job, unsigned j0, unsigned j1) {
    const unsigned first = job.start + j0;
    fill_rows<kLightmap>(column + first, buffers.depth.data() + first, tag, j1 - j0 + 1, job.entry, job.dist);
  }

  // Wall: constant u, depth and light; v advances by v_step (11 fractional bits) per row.
  template <bool kLightmap>
  void wall(const SpanJob& job, unsigned j0, unsigned j1) {
    const Sampler texel(memory, job.binding);
    const unsigned n = j1 - j0 + 1;
    const std::uint32_t column_base = texel.base + (job.u & texel.wmask);  // u is constant down a wall
    const auto light = static_cast<std::uint16_t>(kLightmap ? 0 : light_nibble(job.light, job.dist) << 12);
    const std::uint32_t step = job.v_step, dist_value = job.dist;
    std::uint8_t t[kRows], opaque[kRows];
    std::uint16_t entry[kRows];
    std::uint32_t dist[kRows];
    std::uint32_t v = job.v_fixed + j0 * step;
    for (unsigned i = 0; i < n; ++i, v += step)  // texel gather (scalar)
      t[i] = texel.memory[(column_base + ((((v >> 11) & 255) & texel.hmask) << texel.wp2)) & TextureMemory::kAddressMask];
    for (unsigned i = 0; i < n; ++i) {  // element-wise: vectorises
      entry[i] = static_cast<std::uint16_t>(light | t[i]);
      dist[i] = dist_value;
      opaque[i] = kLightmap || t[i] != kTransparentTexel;
    }
    const unsigned first = job.start + j0;
    write_rows<kLightmap>(column + first, buffers.depth.data() + first, tag, n, entry, dist, opaque);
  }

  // Plane: pixel j's texel uses dot_u/dot_v after j row events and dot_ray after max(j - 1, 0);
  // its depth uses dot_ray after j + 1 (the RTL reads the 1/n table one cycle late and keeps the
  // previous ray_t in the register the depth test reads). So ray_t is computed once per row and
  // used twice: as pixel j's depth and as pixel j + 2's texel coordinate. kFlat: floors and
  // ceilings, whose texture axes have no row component (uy = vy = 0).
  template <bool kLightmap, bool kFlat>
  void plane(const SpanJob& job, unsigned j0, unsigned j1) {
    const Sampler texel(memory, job.binding);
    constexpr unsigned kShift = kLightmap ? 14 : 10;  // lightmaps: one texel per 16 texture texels
    const unsigned n = j1 - j0 + 1;
    const std::int32_t ny = job.ny, uy = job.uy, vy = job.vy, ded = job.ded, u_offset = job.u_offset, v_offset = job.v_offset;
    const unsigned light = job.light;
    const bool background = job.background;
    std::int32_t ray_t[kRows + 2];  // ray_t[k]: dot_ray after j0 - 1 + k events
    std::int32_t dr = wrap24(job.dot_ray + std::int64_t{ny} * (std::int64_t{j0} - 1));
    for (unsigned k = 0; k < n + 2; ++k, dr = wrap24(std::int64_t{dr} + ny)) ray_t[k] = plane_ray_t(dr, ded);
    if (j0 == 0) ray_t[0] = ray_t[1];  // pixel 0's texel uses dot_ray after 0 events, not -1
    std::uint8_t t[kRows], opaque[kRows];
    std::uint16_t entry[kRows];
    std::uint32_t dist[kRows];
    std::int32_t du = wrap24(job.dot_u + std::int64_t{uy} * j0);
    std::int32_t dv = wrap24(job.dot_v + std::int64_t{vy} * j0);
    for (unsigned i = 0; i < n; ++i) {  // texel gather (table and texture loads: scalar)
      const auto u = static_cast<std::uint32_t>(plane_coordinate(ray_t[i], du, u_offset) >> kShift) & 255;
      const auto v = static_cast<std::uint32_t>(plane_coordinate(ray_t[i], dv, v_offset) >> kShift) & 255;
      t[i] = background ? kBackgroundTexel : texel(u, v);
      if constexpr (!kFlat) {
        du = wrap24(std::int64_t{du} + uy);
        dv = wrap24(std::int64_t{dv} + vy);
      }
    }
    for (unsigned i = 0; i < n; ++i) {  // depth, light and entry (element-wise: vectorises)
      dist[i] = static_cast<std::uint32_t>(ray_t[i + 2]) << 1 & 0x7FFFFFFF;
      const unsigned l4 = kLightmap ? 0 : background ? 15 : light_nibble(light, dist[i]);
      entry[i] = static_cast<std::uint16_t>(l4 << 12 | t[i]);
      opaque[i] = kLightmap || t[i] != kTransparentTexel;
    }
    const unsigned first = job.start + j0;
    write_rows<kLightmap>(column + first, buffers.depth.data() + first, tag, n, entry, dist, opaque);
  }

  template <bool kLightmap>
  void pixels(const SpanJob& job, const PixelWrite* writes) {
    for (std::uint32_t i = 0; i < job.writes; ++i) {
      const PixelWrite& w = writes[job.first_write + i];
      if (w.row < lo || w.row > hi) continue;
      fill_rows<kLightmap>(column + w.row, buffers.depth.data() + w.row, tag, 1, w.entry, w.dist);
    }
  }

  template <bool kLightmap>
  void draw(const SpanJob& s, const PixelWrite* writes) {
    if (s.type == JobType::Pixels) return pixels<kLightmap>(s, writes);
    unsigned j0, j1;
    if (!rows(s, j0, j1)) return;
    switch (s.type) {
      case JobType::Fill: fill<kLightmap>(s, j0, j1); break;
      case JobType::Wall: wall<kLightmap>(s, j0, j1); break;
      case JobType::Plane:
        if (s.uy == 0 && s.vy == 0) plane<kLightmap, true>(s, j0, j1);
        else plane<kLightmap, false>(s, j0, j1);
        break;
      default: break;
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
      if (s.type != JobType::EndOfColumn) {
        if (s.lightmap) band.draw<true>(s, fifo.writes.data());
        else band.draw<false>(s, fifo.writes.data());
        continue;
      }
      scanout.column(band.column + band.lo, screen + std::size_t{s.column} * kRows + band.lo, band.hi - band.lo + 1);
      buffer ^= 1;
      band.column = buffers.entries[buffer].data();
      band.tag = buffer << 31;
    }
  };
  pool_.start(job);
  pool_.wait();
}

}  // namespace gpubridge::dmc1
