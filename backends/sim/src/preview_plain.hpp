#pragma once
// The preview routine's plain-draw kernel (`--accuracy preview`, docs/simulator.md "Preview"): the
// draws most scenes are made of — an RGBA8888 buffer, no texture, no write mask, blend OFF or
// ALPHA, depth off or a LESS/LEQUAL/GREATER/GEQUAL/ALWAYS test with or without the Z write —
// specialised per draw (one instance per depth function and blend) and kept in the lane layout
// the memory already has; textured draws of an RGBA8888 texture too (any wrap, nearest or bilinear,
// decal or modulate: the texture stage in lanes, preview_plain_kernel.inc). Other preview draws use
// preview_simd.cpp.
//
// Planes are fixed point, set up once per triangle from the preview setup's double planes
// (FixedPlanes, setup.hpp): colour in 8.24 and Z in 32.32, stepped with integer adds modulo 2^32 /
// 2^64. Integer steps are exact, so a pixel's value does not depend on where the stepping started
// (band, thread, span): the same bytes for any thread count. At box pixel (kx, ky) the fixed-point
// value is within (1 + kx + ky)·2^-25 (colour) / ·2^-33 (Z) of the plane's double value, and a
// covered pixel's value lies inside its vertices' range, so the top bits are the pixel's rounded
// value with no clamp and no float-to-integer conversion in the lanes.
#include <cstddef>
#include <cstdint>

#include "draw_state.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "preview_simd.hpp"

namespace gpubridge::sim {

struct FixedPlanes;
struct FloatPlanes;
struct SmallTriangle;
struct Vertex;

// A textured plain draw's texture: an RGBA8888 texture inside VRAM, disjoint from both buffers.
struct PreviewTexels {
  const std::uint8_t* texels = nullptr;  // the texture's first texel (null: untextured)
  const FloatPlanes* planes = nullptr;   // S, T, Q of the triangle (double, as preview_simd.cpp)
  unsigned wl = 3, hl = 3;               // log2 width / height
  protocol::Wrap wrap_s = protocol::Wrap::Repeat, wrap_t = protocol::Wrap::Repeat;
  bool bilinear = false, decal = false;
  float scale_u = 0, scale_v = 0;        // 2^(20 + log2 size): texel units of 1/4096 per S/Q
};

class HierZ;

// The coarse depth bounds (hier_z.hpp) for a draw the renderer keeps them for (a LESS or LEQUAL
// test, both buffers in VRAM and disjoint): the wide rows skip a span whose smallest depth, in the
// kernel's own arithmetic (preview_span_min_depth), fails against every block it crosses. The
// bounds' generations and the runs' numbers are the exact path's (RasterContext).
struct PreviewBounds {
  HierZ* hier_z = nullptr;              // null: no bounds
  const std::uint8_t* zbuf = nullptr;   // the depth buffer's first word
  std::uint64_t gen = 0;                // RasterContext::hz_gen
  std::uint32_t* run = nullptr;         // RasterContext::hz_run (the last run's number)
  int x0 = 0, y0 = 0;                   // the box origin in pixels (the kernel's kx = 0, ky = 0)
};

// The smallest depth the plain kernel stores or compares over `count` pixels of a row (count >= 1)
// whose 32.32 Z lane is `za` at the first pixel and steps by `zdx` (both modulo 2^64, as the lanes
// hold them): the kernel's depth at a pixel is the lane's high word masked by `zmask`. Every such
// depth is at least `zmin` when this returns true. It returns false (nothing known) unless both
// ends lie in [0, 2^56) and count·|zdx| < 2^56: then the lane's value is the integer za + k·zdx
// with no wrap at every pixel k (it lies between the ends), its high word is below 2^24, where
// masking low bits keeps the order, so the smallest depth is at the end with the smaller lane.
// No margin for float error: the lanes are exact integer sums whatever the double planes were.
inline bool preview_span_min_depth(std::uint64_t za, std::uint64_t zdx, unsigned count, std::uint32_t zmask,
                                   std::uint32_t& zmin) {
  constexpr std::uint64_t kLimit = std::uint64_t{1} << 56;
  const std::uint64_t steps = count - 1u;
  const std::uint64_t zb = za + steps * zdx;
  const std::uint64_t mag = static_cast<std::int64_t>(zdx) < 0 ? 0 - zdx : zdx;
  std::uint64_t reach = 0;
  if (za >= kLimit || zb >= kLimit || __builtin_mul_overflow(steps, mag, &reach) || reach >= kLimit) return false;
  zmin = static_cast<std::uint32_t>((za < zb ? za : zb) >> 32) & zmask;
  return true;
}

struct PreviewPlain {
  std::int64_t e[3], ex[3], ey[3];  // biased edge values at the box origin, steps
  const FixedPlanes* planes = nullptr;
  int width = 0;                    // box width
  int ky0 = 0, rows = 0;            // first row drawn (from the box origin), rows drawn
  std::uint8_t* color = nullptr;    // box origin column, first row drawn
  std::uint8_t* depth = nullptr;    // its depth word (when the draw tests or writes depth)
  std::size_t pitch = 0;            // bytes per row of either buffer (both 4 bytes per pixel)
  unsigned room = 0;                // pixels from the box origin column to the end of a buffer row
  std::uint32_t zmask = 0xFFFFFF;   // the Z bits compared and stored (z_bits)
  protocol::DepthFunc z_func = protocol::DepthFunc::Always;  // with depth: the test (ALWAYS when off)
  protocol::BlendMode blend = protocol::BlendMode::Off;
  bool depth_on = false;            // depth test or write
  bool z_write = false;
  PreviewTexels tex;                // textured draws only
  PreviewBounds bounds;             // LESS / LEQUAL draws with coarse depth bounds only
};

// Whether the plain kernel draws this state (the caller also checks preview_applies): with or
// without an RGBA8888 texture.
bool preview_plain_applies(const DrawState& st);

PreviewCounts shade_preview_plain(const PreviewPlain& t);
// One instance of the kernel shade_preview_plain picks from: 0 the baseline, 1 AVX2, 2 AVX-512
// (chunks of 16 pixels on untextured wide rows); null when this CPU cannot run it. For the tests
// that compare the instances' bytes.
using ShadeRoutine = PreviewCounts (*)(const PreviewPlain& t);
ShadeRoutine shade_instance(unsigned isa);
// The same instance with the flat-Q choice off: every textured triangle divides by Q in every
// chunk of 8 pixels, also where Q's step along x is ±0 (for the tests of that choice).
ShadeRoutine dividing_shade_instance(unsigned isa);

// The count of a rejected band's covered pixels the kernel uses (count_rows in
// preview_plain_kernel.inc: SpanWalk::count in lanes, four rows at a time), leaving the walk after
// the rows as SpanWalk::count does. One instance: 0 the baseline, 1 AVX2, 2 AVX-512; null when
// this CPU cannot run it. For the tests that compare it with SpanWalk::count.
using BandCount = std::uint64_t (*)(SpanWalk& walk, int width, int rows);
BandCount band_count_instance(unsigned isa);

// --- Small triangles (docs/simulator.md "Preview", issue 24) ---
// A triangle of an untextured plain draw whose vertices span at most 255/16 pixel in x and in y
// (so its box is at most 16 x 16 pixels and every edge value at a box pixel is below 2^17) and
// whose box leaves room for 8 words per row (16 for boxes 9 to 16 wide: two groups of 8 lanes)
// takes a setup and a kernel of its own (a sliver of D = 1 spanning more than 127 does not): the
// coverage setup without the vertex copies and the 64-bit generality, the colour planes in four
// double lanes at once and no FloatPlanes, and at draw time the row kernel entered directly
// (no PreviewPlain, no range checks, one kernel per depth function and blend picked per state).
// The planes are the same doubles rounded the same way as setup_triangle_preview's, so the bytes
// are the plain kernel's (SimPreviewSmall.SameBytesAsTheRowKernel).

// The small-triangle kernel of a state + 1, or 0 when the small path does not apply (textured,
// not a plain draw, or the preview routine cannot draw it at all).
std::uint8_t preview_small_kernel(const DrawState& st);

enum class SmallSetup { Empty, Drawn, NotSmall };
// Sets up t for the small-triangle kernel (st.preview_small != 0): Empty when it draws nothing
// (D = 0 or an empty clipped box, as setup_triangle_preview), NotSmall when it is too big (t is
// then unspecified: set it up with setup_triangle_preview).
SmallSetup setup_small_preview(const Vertex& a, const Vertex& b, const Vertex& c, const DrawState& st,
                               unsigned subpixel_bits, SmallTriangle& t);
// Where a small triangle's rows [ky0, ky0 + rows) (from its box origin) are drawn.
struct SmallTarget {
  std::uint8_t* color = nullptr;  // box origin column, first row drawn
  std::uint8_t* depth = nullptr;  // its depth word (when the draw tests or writes depth)
  std::size_t pitch = 0;          // bytes per row of either buffer
  int ky0 = 0, rows = 0;
  std::uint32_t zmask = 0xFFFFFF;  // the Z bits compared and stored (z_bits)
  bool z_write = false;
};

// The same routines of this CPU (AVX2 or the baseline), looked up once per state by the renderer
// instead of on every call (docs/simulator.md "Preview"): same routines, same bytes.
using SmallSetupRoutine = SmallSetup (*)(const Vertex& a, const Vertex& b, const Vertex& c, const DrawState& st,
                                         unsigned subpixel_bits, SmallTriangle& t);
using SmallKernel = PreviewCounts (*)(const SmallTriangle& t, const SmallTarget& d);
SmallSetupRoutine small_setup_routine();
// One instance of the small setup: 0 the baseline, 1 AVX2, 2 AVX-512; null when this CPU cannot run
// it. For the tests that compare the instances (the renderer uses small_setup_routine).
SmallSetupRoutine small_setup_instance(unsigned isa);
SmallKernel small_kernel(const DrawState& st);  // st.preview_small != 0

}  // namespace gpubridge::sim
