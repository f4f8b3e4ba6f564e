#pragma once
// The SDRAM row model's input from the simulated draw (timing.hpp SdramRows, docs/protocol.md
// section 19): the covered spans of a set-up triangle with the depth and colour addresses its
// pixels touch, in the order the gateware walks them (rows top to bottom, pixels left to right).
// Timing only: it reads the triangle's edges and the draw state, never video memory.
#include "draw_state.hpp"
#include "gpubridge/sim/timing.hpp"
#include "setup.hpp"

namespace gpubridge::sim {

// Every covered span of t (its clipped box, its biased edge functions) into `rows`, with the
// depth and colour accesses the draw state asks for. Every covered pixel is charged as if it
// passed the depth test (whether it does is known only once the triangles before it are drawn).
// A textured triangle's pixels also look their texels up in `texels` (the ecp5's texel cache:
// the texel indices from the vertices' s, t, q in double precision, not the exact reciprocal,
// which moves an index by one only at a texel's edge), and each miss is a texel read in the
// stream between the pixel's depth accesses and its colour word. Returns the covered pixels.
std::uint64_t access_triangle_rows(SdramRows& rows, TexelCache& texels, const Triangle& t, const DrawState& st);

// The pixels of a depth-class triangle of `covered` pixels still in the ecp5's depth stage when
// its walk ends (its reads in flight: 4, core_depth.v with AW = 2): their memory work drains under
// the next triangle's setup, not in the rasteriser's clocks (DeviceStats::depth_tail_pixels).
constexpr std::uint64_t kDepthReadsInFlight = 4;
inline std::uint64_t depth_tail_pixels(std::uint64_t covered) { return covered < kDepthReadsInFlight ? covered : kDepthReadsInFlight; }

// The texture bytes a textured triangle of `covered` pixels can fetch at most through a texel
// cache: its footprint in texture space (the texels inside the triangle of its vertices' texel
// coordinates, plus a border of one for bilinear's second row and column), never more than its
// samples fetch without one (covered x 1 or 4 texels). Perspective and wrapping make it an
// estimate; without a usable q (0) it is the samples' bytes.
std::uint64_t texel_footprint_bytes(const Triangle& t, const DrawState& st, std::uint64_t covered);

}  // namespace gpubridge::sim
