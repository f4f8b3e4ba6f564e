#pragma once
// The host triangle pipeline: what the seeds' host CPUs do before the GPU sees a triangle.
//
//   window-homogeneous triangle (X, Y, Z, W, colour, u, v)
//     → near-plane clip (Z >= 0), 0..2 triangles, Foenix style; far plane (Z <= W) optional
//     → W >= min_w clip (only matters for matrices that are not perspective()/orthographic())
//     → guard-band clip when a vertex lies outside the band (2D lines as homogeneous planes)
//     → texture-precision subdivision (textured triangles only, see below)
//     → perspective divide → snap/convert (convert_triangle) → back-face / zero-area cull
//     → rejection of triangles that cannot cover a pixel of the visible rectangle (when given)
//
// Screen-space input (scene files, draw::Context::draw_screen) enters through
// process_screen_triangle: the same pipeline on (x·w, y·w, z·w, w), except that every vertex the
// user gave is snapped from the x, y (and converted from the z) the user gave, whatever w is.
// Only vertices the pipeline creates (clip intersections, subdivision midpoints) are snapped from
// their perspective divide (docs/protocol.md 16.2).
//
// Texture-precision subdivision: the device's texel-coordinate error is ≤ 1/256 texel for
// 1024-texel textures (docs/protocol.md section 15) when, within a triangle, max W / min W ≤ 32
// and |u − u_off|, |v − v_off| ≤ 4 texture sizes. The pipeline splits every EDGE whose two
// endpoints violate the bound (W ratio > max_w_ratio, or U or V differing by more than
// max_uv_extent = 3, which keeps |u − floor(min u)| < 4) at its homogeneous midpoint; that
// halves the edge's U/V extent and pulls its W ratio towards 1. A triangle's vertex pairs are
// exactly its edges, so a triangle whose edges all pass meets the bound; and because the
// decision and the midpoint depend only on the edge's two endpoints, neighbouring triangles split
// a shared edge identically (no T-junctions). Depth is limited (max_subdivision_depth); triangles
// still over the bound at the limit are
// emitted anyway and counted in PipelineStats::precision_exceeded.
#include <cstddef>
#include <optional>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/geometry/clip.hpp"
#include "gpubridge/geometry/convert.hpp"

namespace gpubridge::geometry {

enum class CullMode { None, Back, Front };
// Which on-screen winding is the front face, as seen on the display (y down).
enum class FrontFace { CounterClockwise, Clockwise };

// The pixels the device considers for a triangle (docs/protocol.md 8.5): x in [x0, x1), y in
// [y0, y1), i.e. the framebuffer intersected with SCISSOR. Empty when x1 <= x0 or y1 <= y0.
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  friend bool operator==(const PixelRect&, const PixelRect&) = default;
};
// [max(0, scissor x0), min(width, scissor x1)) and the same for y.
PixelRect visible_rect(unsigned width, unsigned height, unsigned sx0, unsigned sy0, unsigned sx1, unsigned sy1);

// True when no pixel of `rect` can be covered by the snapped triangle: every covered pixel's
// sample point (16x + 8, 16y + 8) lies inside the closed triangle (section 8.4: all three edge
// functions >= 0), hence inside its bounding box, so a triangle whose bounding box holds no
// sample point of the rectangle draws nothing there. Exact integer test, no false positives.
bool covers_no_pixel(const DeviceTriangle& t, const PixelRect& rect);

struct PipelineOptions {
  CullMode cull = CullMode::None;
  FrontFace front_face = FrontFace::CounterClockwise;
  bool clip_far = true;            // also clip Z <= W (depth 1)
  double min_w = 1e-6;             // W below this is clipped away (protects 1/W)
  GuardBand guard_band{};
  bool textured = false;           // enables S/T (TEXCOORD) and precision subdivision
  TexAddressing tex{};
  bool subdivide = true;           // texture-precision subdivision (textured only)
  double max_w_ratio = 32.0;       // bound on max W / min W per triangle for 1024-texel textures
  unsigned texture_size = 1024;    // larger of the bound texture's width and height: the W-ratio
                                   // bound scales by 1024 / texture_size (docs section 16.6)
  double max_uv_extent = 3.0;      // bound on max−min of U and of V: keeps |u − u_off| < 4
  unsigned max_subdivision_depth = 6;  // at most 4^depth triangles per clipped triangle
  // When set, triangles that cannot cover a pixel of this rectangle (covers_no_pixel: wholly
  // left, right, above or below it after snapping) are not sent; the device would draw nothing
  // for them (docs/protocol.md 16.7). Unset: every triangle the planes keep is sent.
  std::optional<PixelRect> visible;
};

struct PipelineStats {
  std::size_t input = 0;               // triangles given to the pipeline
  std::size_t clipped_away = 0;        // entirely outside the near/far/guard planes
  std::size_t clipped = 0;             // triangles that needed clipping and kept some area
  std::size_t subdivided = 0;          // triangles split for texture precision
  std::size_t precision_exceeded = 0;  // emitted although over the precision bound (depth limit)
  std::size_t culled = 0;              // back/front-facing or zero area after snapping
  std::size_t outside = 0;             // not culled but covering no pixel of opt.visible
  std::size_t emitted = 0;             // device triangles produced
};

// Signed area ×2 of the snapped triangle in 12.4 units, y down: negative = counter-clockwise
// on screen.
std::int64_t signed_area2(const DeviceTriangle& t);

// The clipping stage of process_triangle (near, far, W >= min_w, then the guard band when a
// vertex lies outside it). The polygon points into `tri` when no plane cut it, else into
// `buffers`; count 0 when nothing is left. `clipped` says whether any plane cut it.
struct ClipBuffers {
  ClipBuffer a, b;
};
struct ClippedPolygon {
  PolygonView polygon;
  bool clipped = false;
};
ClippedPolygon clip_for_pipeline(const Triangle& tri, const PipelineOptions& opt, ClipBuffers& buffers);

// Runs one window-homogeneous triangle through the pipeline, appending device triangles.
// Errors: non-finite input (NaN/Inf in any position, colour or texture coordinate), or a texture
// coordinate range that S/T cannot hold even after subdivision.
Result<void> process_triangle(const Triangle& tri, const PipelineOptions& opt, std::vector<DeviceTriangle>& out,
                              PipelineStats* stats = nullptr);

// Runs one screen-space triangle (x, y in pixels, z in [0, 1], w > 0 the perspective divisor)
// through the pipeline. Differs from process_triangle(from_screen(...)) only in the snapping of
// the given vertices: floor(16·x + 0.5) of the x given, exactly, also where x·w / w is not x.
Result<void> process_screen_triangle(const std::array<ScreenVertex, 3>& tri, const PipelineOptions& opt,
                                     std::vector<DeviceTriangle>& out, PipelineStats* stats = nullptr);

// Window-homogeneous vertex from a screen-space vertex: (x·w, y·w, z·w, w).
Vertex from_screen(const ScreenVertex& v);
// Perspective divide (W must be > 0).
ScreenVertex to_screen(const Vertex& v);

}  // namespace gpubridge::geometry
