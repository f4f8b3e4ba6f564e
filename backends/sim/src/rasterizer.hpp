#pragma once
// The rasteriser (docs/protocol.md sections 8-11 per pixel): walks the covered pixels of a set-up
// triangle row by row, steps the exact attribute planes, and runs the texture unit and the pixel
// pipeline. Per draw it picks a routine specialised on the render state (Gouraud, textured, depth,
// plain RGBA8888 store) so disabled features cost nothing. Rows can be restricted to a band so
// several workers can share a triangle with identical results.
#include <cstdint>

#include "draw_state.hpp"
#include "hier_z.hpp"
#include "preview_plain.hpp"
#include "gpubridge/sim/device.hpp"
#include "reciprocal.hpp"
#include "setup.hpp"
#include "video_memory.hpp"

namespace gpubridge::sim {

struct RasterCounters {
  std::uint64_t scanned = 0, covered = 0, passed = 0, textured = 0, blended = 0, texel_bytes = 0;
  void add(const RasterCounters& o) {
    scanned += o.scanned;
    covered += o.covered;
    passed += o.passed;
    textured += o.textured;
    blended += o.blended;
    texel_bytes += o.texel_bytes;
  }
};

struct RasterContext {
  VideoMemory& mem;
  const ReciprocalUnit& recip;
  unsigned z_bits = 24;
  std::uint16_t errors = 0;  // ERR_MEM_RANGE from out-of-memory accesses
  RasterCounters counters;
  bool vector = true;  // vector routines allowed (DeviceOptions::vector_routines)
  // Coarse depth bounds (hier_z.hpp) when the renderer keeps them for this draw's state (its
  // depth test LESS or LEQUAL, buffers in VRAM and disjoint), their generation, and the number of
  // the last Kernel run drawn with this context.
  HierZ* hier_z = nullptr;
  std::uint64_t hz_gen = 0;
  std::uint32_t hz_run = 0;
  // Covered pixels the coarse depth rejected before the span routine (whole bands and single rows
  // of the exact kernel), counted in the covered pixels but not shaded, and the rows of the whole
  // bands (not walked: a row rejected alone was). The band workers' measured work
  // (BandSplit::measured_work) takes them off: random-Z scenes reject most of their pixels,
  // unevenly down the screen, where the estimate cannot see it.
  std::uint64_t hz_skipped_pixels = 0, hz_skipped_rows = 0;
};

// The preview routine (`--accuracy preview`, preview_simd.hpp) can draw with this state: both
// buffers inside VRAM and disjoint, a texture inside VRAM disjoint from both, a colour stage that
// is not fully masked. Other draws take the exact path (setup_triangle) even in preview mode.
bool preview_applies(const DrawState& st);

// What drawing a small preview triangle (SmallTriangle, preview_plain.hpp) needs from its state,
// worked out once per state (the renderer keeps it while the state lasts) instead of per triangle.
struct SmallDraw {
  SmallKernel kernel = nullptr;   // small_kernel(st)
  std::uint8_t* color = nullptr;  // the colour buffer's first pixel
  std::uint8_t* depth = nullptr;  // the depth buffer's first word (null without depth)
  std::size_t pitch = 0;          // bytes per row of either buffer
  unsigned width = 0;             // pixels per row
  std::uint32_t zmask = 0xFFFFFF; // the Z bits compared and stored (z_bits)
  bool z_write = false, blended = false;
};
// For a state with st.preview_small != 0 (and preview_applies).
SmallDraw small_draw(const DrawState& st, VideoMemory& mem, unsigned z_bits);
// Draws the rows [row_begin, row_end) of a small triangle's compact record (clipped to its box) as
// rasterize_rows would draw the triangle, counting into c. Inline: the renderer calls it once per
// small triangle.
[[gnu::always_inline]] inline void rasterize_small(const SmallTriangle& t, const SmallDraw& d, RasterCounters& c,
                                                   int row_begin, int row_end) {
  const int ya = row_begin > t.y0 ? row_begin : t.y0, yz = row_end < t.y1 ? row_end : t.y1;
  if (ya >= yz) return;
  SmallTarget s;
  const std::size_t pix = static_cast<std::size_t>(ya) * d.width + static_cast<std::size_t>(t.x0);
  s.color = d.color + pix * 4;
  if (d.depth) s.depth = d.depth + pix * 4;
  s.pitch = d.pitch;
  s.ky0 = ya - t.y0;
  s.rows = yz - ya;
  s.zmask = d.zmask;
  s.z_write = d.z_write;
  const PreviewCounts n = d.kernel(t, s);
  c.scanned += n.scanned;  // count_drawn's counts
  c.covered += n.covered;
  c.passed += n.passed;
  if (d.blended) c.blended += n.passed;
}

// Draws the rows [row_begin, row_end) of t (a preview triangle through the preview routine) (clipped to its bounding box) with state st.
void rasterize_rows(const Triangle& t, const DrawState& st, RasterContext& ctx, int row_begin, int row_end);
// The slow, obviously exact path for --dump-attributes: reports every covered pixel's attribute
// values as N / D (section 9) in double.
void observe_triangle(const Triangle& t, const DrawState& st, const PixelObserver& observer);

}  // namespace gpubridge::sim
