#include "rasterizer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <utility>

#include "color_cursor.hpp"
#include "narrow_simd.hpp"
#include "pixel.hpp"
#include "preview_plain.hpp"
#include "preview_simd.hpp"
#include "span_simd.hpp"
#include "texture.hpp"

namespace gpubridge::sim {
namespace {

using protocol::Rgba8;

struct Steppers {
  std::int64_t q[kAttrCount], r[kAttrCount];
};

// No texel the draw samples lies in a buffer it writes (the vector routines sample eight texels
// before they write eight pixels).
bool texture_disjoint(const DrawState& st, bool depth) {
  const std::uint64_t tlen = (std::uint64_t{1} << (st.tex.wl + st.tex.hl)) * protocol::bytes_per_pixel(st.tex.format);
  const std::uint64_t pixels = std::uint64_t{st.fb_width} * st.fb_height;
  auto apart = [&](std::uint64_t base, std::uint64_t len) { return st.tex.base + tlen <= base || base + len <= st.tex.base; };
  return apart(st.fb_draw, pixels * st.bpp) && (!depth || apart(st.fb_z, pixels * 4));
}

// The Z bits a depth buffer of ctx.z_bits precision compares and stores.
std::uint32_t z_mask(const RasterContext& ctx) {
  return ctx.z_bits >= 24 ? 0xFFFFFFu : 0xFFFFFFu & ~((1u << (24 - ctx.z_bits)) - 1);
}

// The vector routines' pixel stage for a draw (pixel_lanes.hpp): colour `flat` when !gouraud,
// the depth test and write only when `depth` (the routine has a depth buffer). The texture stage
// is the caller's.
inline void set_pixel_lanes(PixelLanes& px, const DrawState& st, const RasterContext& ctx, Rgba8 flat, bool gouraud,
                     bool depth) {
  px.flat = std::uint32_t{flat.r} | (std::uint32_t{flat.g} << 8) | (std::uint32_t{flat.b} << 16) |
            (std::uint32_t{flat.a} << 24);
  px.zmask = z_mask(ctx);
  px.format = st.fb_format;
  px.z_func = st.z_func;
  px.blend = st.blend;
  px.keep = st.keep_bits;
  px.temporal = st.dither.temporal && st.fb_format != protocol::PixelFormat::RGBA8888;
  px.gouraud = gouraud;
  px.z_test = depth && st.z_test;
  px.z_write = depth && st.z_write;
}

// Boxes this wide or wider find each row's covered span from the edge walk instead of testing every
// pixel of the box row (boxes up to 8 wide take the small-triangle routine, narrow_simd.hpp).
constexpr int kSpanSolveWidth = 16;
// So do boxes of 9-15 pixels at least this tall (tall slivers: the fan's near-vertical ones), which
// cost less walked than tested pixel by pixel (fan 0.400 -> 0.350 G instructions). Short ones keep
// the pixel test: walked, the 10-px triangles lost 10 % CPU time for 1 % fewer instructions.
constexpr int kSpanSolveTall = 24;
// Whether t's rows take the edge walk (Kernel::run_wide).
inline bool walks_rows(const Triangle& t) {
  const int w = t.x1 - t.x0;
  return w >= kSpanSolveWidth || (w > 8 && t.y1 - t.y0 >= kSpanSolveTall);
}
// Jumps along a row shorter than this are stepped instead of divided (the cursor's anchor).
constexpr std::int64_t kStepJump = 4;
// Rows this far ahead of the one being drawn are prefetched.
constexpr int kPrefetchRows = 4;

// The edge walk's divisors: each edge's |ex| (1 for a vertical edge, never divided by). A wide
// row's covered span kl..kr (box-relative) is where E + k·ex >= 0 for all three edges:
// k >= ceil(−E / ex) = −floor(E / ex) for ex > 0, k <= floor(E / −ex) for ex < 0.
inline Divider edge_divider(const Edge& e) { return Divider(e.ex < 0 ? -e.ex : (e.ex == 0 ? 1 : e.ex)); }

// The edge walk of a wide box (w >= kSpanSolveWidth): (q, r) = floor-divmod of each edge value by
// its |ex| (the span bounds' quotients), stepped a row at a time by floor-divmod(ey, |ex|) and one
// carry: the same integers as dividing on every row, with no division a row.
//
// Strips: a row whose sample line lies above the middle vertex (in y) is bounded by the two edges
// of the top vertex, one on either side; the third edge (middle to bottom) lies below that line,
// so every sample between the two lies in the closed triangle off the third edge's line, where its
// exact edge value is positive: at least 1, so at least 0 with the top-left bias (section 8.3) as
// well. Below the middle vertex's line the same holds for the bottom vertex's two edges. Those rows
// walk two edges, with the left and right one known per triangle (no test of ex's sign a row); the
// edge a strip skips is not stepped and is started afresh (one division) when a later row needs it.
// The middle vertex's own line walks all three. Triangles with a horizontal edge (ex == 0) walk all
// three on every row.
struct EdgeWalk {
  std::int64_t q[3], r[3], qy[3], ry[3], d[3];
  const Divider* div = nullptr;  // the edges' dividers (edge_divider)
  bool strips = false;
  int upper_end = 0, lower_begin = 0;  // rows < upper_end: the upper pair; rows >= lower_begin: the lower pair
  int up_lo = 0, up_hi = 0, up_skip = 0;  // the upper pair's left (ex > 0) and right (ex < 0) edge, the edge it skips
  int dn_lo = 0, dn_hi = 0, dn_skip = 0;  // the lower pair's
  unsigned up_bit = 0, dn_bit = 0, dn_need = 0;  // 1 << up_skip, 1 << dn_skip, the lower pair's edges
  unsigned stale = 0;                     // edges a strip skipped since they were last started
  // The row steps and the strips (once per triangle; div: the edges' dividers, edge_divider, which
  // must outlive the walk).
  void prepare(const Triangle& t, const Divider d_[3]) {
    div = d_;
    for (int i = 0; i < 3; ++i) {
      const DivMod s = div[i](t.edge[i].ey);
      qy[i] = s.q;
      ry[i] = s.r;
      d[i] = div[i].divisor();
    }
    strips = false;
    for (int i = 0; i < 3; ++i)
      if (t.edge[i].ex == 0) return;  // a horizontal edge: vertices share a y
    // Edge i joins the two vertices other than i. No edge is horizontal, so the y differ.
    int top = 0, mid = 1, bot = 2;
    if (t.v[mid].y < t.v[top].y) std::swap(mid, top);
    if (t.v[bot].y < t.v[mid].y) std::swap(bot, mid);
    if (t.v[mid].y < t.v[top].y) std::swap(mid, top);
    // Upper rows: the edges of the top vertex (edge[mid], edge[bot]); lower: of the bottom vertex.
    if (!pair(t, mid, bot, up_lo, up_hi) || !pair(t, mid, top, dn_lo, dn_hi)) return;
    up_skip = top;
    dn_skip = bot;
    up_bit = 1u << up_skip;
    dn_bit = 1u << dn_skip;
    dn_need = 7u & ~dn_bit;
    // Row y's sample line is 16y + 8 (1/16 pixel).
    const std::int64_t m = t.v[mid].y - 8;
    upper_end = static_cast<int>(ceil_div(m, 16));        // first row with 16y + 8 >= the middle vertex's y
    lower_begin = static_cast<int>(floor_div(m, 16) + 1);  // first row with 16y + 8 > it
    strips = true;
  }
  // Edges a and b as a pair: lo the one with ex > 0 (it bounds the span's left end), hi ex < 0.
  static bool pair(const Triangle& t, int a, int b, int& lo, int& hi) {
    if (t.edge[a].ex > 0 && t.edge[b].ex < 0) {
      lo = a, hi = b;
      return true;
    }
    if (t.edge[b].ex > 0 && t.edge[a].ex < 0) {
      lo = b, hi = a;
      return true;
    }
    return false;
  }
  // Edge i's quotient at box row y (absolute).
  void start_edge(const Triangle& t, int i, int y) {
    const DivMod a = div[i](t.edge[i].e + static_cast<std::int64_t>(y - t.y0) * t.edge[i].ey);
    q[i] = a.q;
    r[i] = a.r;
  }
  // The quotients of box row y (absolute).
  void start(const Triangle& t, int y) {
    for (int i = 0; i < 3; ++i) start_edge(t, i, y);
    stale = 0;
  }
  // The stale edges among `mask` started afresh at row y.
  [[gnu::noinline]] void refresh(const Triangle& t, unsigned mask, int y) {
    for (int i = 0; i < 3; ++i)
      if ((stale & mask) >> i & 1) start_edge(t, i, y);
    stale &= ~mask;
  }
  [[gnu::always_inline]] void step(int i) {
    q[i] += qy[i];
    r[i] += ry[i];
    const bool carry = r[i] >= d[i];
    r[i] -= carry ? d[i] : 0;
    q[i] += carry;
  }
  // Row y's covered span kl..kr (box-relative; empty when kl > kr), then on to the next row. Rows
  // are walked in increasing order.
  [[gnu::always_inline]] void span_and_step(const Triangle& t, int y, std::int64_t w, std::int64_t& kl,
                                            std::int64_t& kr) {
    if (strips) {
      int lo, hi;
      if (y < upper_end) {
        lo = up_lo, hi = up_hi;
        stale |= up_bit;
      } else if (y >= lower_begin) {
        if (stale & dn_need) refresh(t, dn_need, y);
        lo = dn_lo, hi = dn_hi;
        stale |= dn_bit;
      } else {
        if (stale) refresh(t, 7u, y);
        return span_all(t, w, kl, kr);
      }
      kl = std::max<std::int64_t>(0, -q[lo]);
      kr = std::min<std::int64_t>(w - 1, q[hi]);
      step(lo);
      step(hi);
      return;
    }
    span_all(t, w, kl, kr);
  }
  // span_and_step over all three edges.
  [[gnu::always_inline]] void span_all(const Triangle& t, std::int64_t w, std::int64_t& kl, std::int64_t& kr) {
    kl = 0;
    kr = w - 1;
    for (int i = 0; i < 3; ++i) {
      const std::int64_t ex = t.edge[i].ex;
      if (ex > 0) kl = std::max(kl, -q[i]);
      else if (ex < 0) kr = std::min(kr, q[i]);
      else if (q[i] < 0) kr = -1;
      step(i);
    }
  }
  // What drawing rows y.. y + rows - 1 counts when all their pixels fail the depth test: every
  // covered pixel scanned and covered, none passed. Leaves the walk after them. Returns the count.
  std::uint64_t count(const Triangle& t, int y, int rows, RasterCounters& c) {
    const std::int64_t w = t.x1 - t.x0;
    std::uint64_t n = 0;
    for (int row = 0; row < rows; ++row) {
      std::int64_t kl, kr;
      span_and_step(t, y + row, w, kl, kr);
      n += kl <= kr ? static_cast<std::uint64_t>(kr - kl + 1) : 0u;
    }
    c.scanned += n;
    c.covered += n;
    return n;
  }
};

// The triangle's edges as band_occluded clips them: edge i runs from its lower end (y0, x0, z0)
// up to y1 (sample units), x and the interpolated depth changing by kx, kz per unit of y. Worked
// out once per triangle (a division per edge) for all the bands it asks.
struct BandClip {
  double y0[3], y1[3], x0[3], z0[3], kx[3], kz[3];
  explicit BandClip(const Triangle& t) {
    for (int i = 0; i < 3; ++i) {
      const Vertex* a = &t.v[i];
      const Vertex* b = &t.v[i == 2 ? 0 : i + 1];
      if (b->y < a->y) std::swap(a, b);
      y0[i] = a->y;
      y1[i] = b->y;
      x0[i] = a->x;
      z0[i] = a->z;
      // A horizontal edge's ends are the ends of the other two edges: it adds nothing (y1 < y0 skips it).
      if (b->y == a->y) {
        y1[i] = y0[i] - 1;
        kx[i] = kz[i] = 0;
        continue;
      }
      const double inv = 1.0 / (static_cast<double>(b->y) - a->y);
      kx[i] = (static_cast<double>(b->x) - a->x) * inv;
      kz[i] = (static_cast<double>(b->z) - a->z) * inv;
    }
  }
};

// Whether the coarse depth bounds (hier_z.hpp) reject every covered pixel of t's rows ya..yb
// (inclusive, inside one 16-row band of blocks), asked as Kernel run `run`. The depth plane is the
// affine interpolation of the vertices' depths (section 9: the weights are the raw edge functions,
// none negative at a covered sample point, rounded to nearest), so at a covered pixel of these rows
// the depth is at least the floor of the plane's least value over the part of the triangle between
// the rows' sample lines y = 16·ya + 8 and 16·yb + 8; that part is convex and its corners lie on
// the edges clipped to those lines, so the least value is at an end of a clipped edge (c). Found in
// double, with a margin of one depth unit for rounding: a lower bound, masked as the test masks
// (masking keeps order). The columns asked are those ends' pixel columns and one more either side,
// inside the box. Every pixel of the rows then fails the test as in Kernel::occluded. Asked before
// a Kernel is built, a rejected band costs its span solves only.
bool band_occluded(const Triangle& t, const BandClip& c, const DrawState& st, RasterContext& ctx, std::uint32_t zmask,
                   int ya, int yb, std::uint32_t run) {
  const double lo = 16.0 * ya + 8, hi = 16.0 * yb + 8;
  double zmin = HUGE_VAL, xmin = HUGE_VAL, xmax = -HUGE_VAL;
  for (int i = 0; i < 3; ++i) {
    const double a = std::max(lo, c.y0[i]) - c.y0[i], b = std::min(hi, c.y1[i]) - c.y0[i];
    if (a > b) continue;  // the edge does not reach these rows
    const double xa = c.x0[i] + a * c.kx[i], xb = c.x0[i] + b * c.kx[i];
    const double za = c.z0[i] + a * c.kz[i], zb = c.z0[i] + b * c.kz[i];
    zmin = std::min(zmin, std::min(za, zb));
    xmin = std::min(xmin, std::min(xa, xb));
    xmax = std::max(xmax, std::max(xa, xb));
  }
  if (zmin == HUGE_VAL) return false;  // no part of the triangle in these rows (nothing to skip)
  const double zf = std::floor(zmin) - 1;
  const std::uint32_t z = zf <= 0 ? 0u : zf >= 0xFFFFFF ? 0xFFFFFFu : static_cast<std::uint32_t>(zf);
  // Pixel x's sample point is 16x + 8.
  const int xa = std::max(t.x0, static_cast<int>(std::floor((xmin - 8) * (1.0 / 16))) - 1);
  const int xb = std::min(t.x1 - 1, static_cast<int>(std::ceil((xmax - 8) * (1.0 / 16))) + 1);
  if (xa > xb) return false;
  return ctx.hier_z->occludes(ctx.mem.data() + st.fb_z, ya, xa, xb, z & zmask, st.z_func == protocol::DepthFunc::Less,
                              ctx.hz_gen, run);
}

// Asks t's rows ya..yb (one 16-row band) as band_occluded does and gives the band's backoff the
// answer (HierZ::band_answered); the edges are clipped (`clip`) the first time the triangle asks.
// For rasterize_rows's leading bands and the Kernel's later ones alike.
bool ask_band(const Triangle& t, std::optional<BandClip>& clip, const DrawState& st, RasterContext& ctx,
              std::uint32_t zmask, int ya, int yb, std::uint32_t run) {
  if (!clip) clip.emplace(t);
  const bool rejected = band_occluded(t, *clip, st, ctx, zmask, ya, yb, run);
  ctx.hier_z->band_answered(ya >> HierZ::kRowsLog, rejected);
  return rejected;
}

// What rasterize_rows's band tests found before the Kernel was built (Kernel::run's `hz`).
constexpr unsigned kHzFirstAsked = 1;  // the first band of the run was asked and not rejected (or let pass)
constexpr unsigned kHzRejected = 2;    // bands before the run were rejected

template <bool kGouraud, bool kTextured, bool kDepth, bool kSimple>
class Kernel {
 public:
  static constexpr unsigned kPlanes = (kGouraud ? 0x0Fu : 0u) | (kDepth ? 1u << kZ : 0u) | (kTextured ? 0xE0u : 0u);
  // Shortest span handed to the vector routine. A textured pixel costs the scalar routine a
  // reciprocal and four texel reads one by one, so even two-pixel spans win in lanes (cubes
  // +5 %, road +1 %, A/B alternating x3); untextured pixels are cheap enough scalar below 8
  // (sending them to the routine saved 1.4 % of the instructions on 1,000-px triangles but cost
  // the fan's 1-7-pixel spans about a fifth of its rate).
  static constexpr std::int64_t kMinSimdSpan = kTextured ? 2 : 8;

  Kernel(const Triangle& t, const DrawState& st, RasterContext& ctx)
      : t_(t), st_(st), ctx_(ctx), tex_(st.tex, ctx.mem), den_div_(t.den) {
    width_ = st.fb_width;
    color_ = ctx.mem.data() + st.fb_draw;
    zbuf_ = ctx.mem.data() + st.fb_z;
    zmask_ = z_mask(ctx);
    const std::uint8_t stored = st.fb_format == protocol::PixelFormat::RGB565 ? 0x7 : 0xF;
    skip_color_ = (st.keep_mask & stored) == stored;
    plain_rgba_ = kSimple && !skip_color_ && st.color_in_vram;
    if (kGouraud) {
      flat_ = {};
    } else if (st.gouraud) {  // Gouraud requested but every vertex has the same colour
      flat_ = {t.v[0].c[0], t.v[0].c[1], t.v[0].c[2], t.v[0].c[3]};
    } else {
      flat_ = {t.flat[0], t.flat[1], t.flat[2], t.flat[3]};
    }
    if (walks_rows(t)) {  // only walked rows need the edge steps
      for (int i = 0; i < 3; ++i) {
        edge_div_[i] = edge_divider(t.edge[i]);
      }
      walk_.prepare(t, edge_div_);
    }
    if (kTextured && t.plane[kQ].constant && t.plane[kQ].q != 0) {
      q_const_ = true;  // affine: the reciprocal is the same at every pixel
      const_rc_ = ctx.recip(static_cast<std::uint32_t>(t.plane[kQ].q));
    }
  }

  // Rows ya..yz-1, once per Kernel. `hz` (kHzFirstAsked, kHzRejected) tells what the caller's band
  // tests found before the Kernel was built (rasterize_rows): the first band was asked and not
  // rejected, and whether bands before ya were rejected.
  void run(int ya, int yz, unsigned hz) {
    if (kDepth && ctx_.hier_z) {
      hz_run_ = HierZ::next_run(ctx_.hz_run);
      hz_tries_ = HierZ::kTries;
      hz_rejected_ = (hz & kHzRejected) != 0;
    }
    const std::uint64_t passed_before = ctx_.counters.passed;
    int mark_from;
    if (!walks_rows(t_)) mark_from = run_narrow(ya, yz);
    else if (kGouraud && ctx_.vector && t_.den < (std::int64_t{1} << 30)) mark_from = run_wide<true>(ya, yz, hz);
    else mark_from = run_wide<false>(ya, yz, hz);
    // Blocks this run wrote into: read again when another run asks (their bounds only got looser).
    if (kDepth && ctx_.hier_z && st_.z_write && ctx_.counters.passed != passed_before)
      ctx_.hier_z->mark(mark_from, yz, t_.x0, t_.x1 - 1, hz_run_);
    if constexpr (kTextured) {
      ctx_.counters.textured += textured_;
      ctx_.counters.texel_bytes += textured_ * (st_.tex.bilinear ? 4u : 1u) * protocol::bytes_per_pixel(st_.tex.format);
    }
  }

 private:
  // Narrow boxes (no span routine): every pixel of the box row is tested and stepped. The loop
  // count is the same on every row of the triangle, so it predicts; stepping only along the
  // covered run was tried and lost on tall slivers (its data-dependent loop exits mispredicted on
  // every row). Returns the first row a pixel may have been written in.
  int run_narrow(int ya, int yz) {
    const int w = t_.x1 - t_.x0;
    const std::int64_t k = ya - t_.y0;
    std::int64_t e0 = t_.edge[0].e + k * t_.edge[0].ey, e1 = t_.edge[1].e + k * t_.edge[1].ey,
                 e2 = t_.edge[2].e + k * t_.edge[2].ey;
    const std::int64_t x0 = t_.edge[0].ex, x1 = t_.edge[1].ex, x2 = t_.edge[2].ex;
    Steppers row = anchor(ya, 0);
    for (int y = ya; y < yz; ++y) {
      Steppers s = row;
      std::int64_t f0 = e0, f1 = e1, f2 = e2;
      for (int kx = 0; kx < w; ++kx) {
        if ((f0 | f1 | f2) >= 0) {
          ++ctx_.counters.covered;
          if constexpr (!kDepth) ++ctx_.counters.passed;  // pixel() counts only depth-tested passes
          pixel(t_.x0 + kx, y, s, rgba_of(s));
        }
        f0 += x0;
        f1 += x1;
        f2 += x2;
        step_x(s);
      }
      ctx_.counters.scanned += static_cast<std::uint64_t>(w);
      e0 += t_.edge[0].ey;
      e1 += t_.edge[1].ey;
      e2 += t_.edge[2].ey;
      step_y(row);
    }
    return ya;
  }

  // Wide boxes: each row's covered span kl..kr from the edge walk (walk_, an EdgeWalk: no division a row; a rejected band is counted through it and the walk goes on),
  // the planes kept at the span's first pixel by a cursor that one combined step a row carries to
  // the next row's first pixel (cur_, move), spans of kMinSimdSpan pixels or more through the span
  // routine, shorter ones pixel by pixel. Whole 16-row bands are asked first (band_occluded); rows
  // of a band that is not rejected are asked one by one (occluded). Returns the first row a pixel
  // may have been written in. kLanes: the colour planes of the cursor and of short spans step in one
  // 4-lane vector (color_cursor.hpp; Gouraud draws with den < 2^30), the other planes as scalars.
  template <bool kLanes>
  int run_wide(int ya, int yz, unsigned hz) {
    constexpr unsigned kScalar = scalar_planes<kLanes>();
    if constexpr (kLanes) prepare_lanes();
    const int w = t_.x1 - t_.x0;
    const bool bands = kDepth && ctx_.hier_z;
    int mark_from = ya;
    bool first = true;
    bool walking = false;  // walk_ holds row y's quotients
    bool anchored = false;  // cur_ holds the planes at (y - 1, col_) (false before the first drawn row and after a rejected band)
    // Covered pixels of drawn rows, and those of short spans without depth (all pass): counted
    // here and added to the context once per run, not stored through ctx_ on every row.
    std::uint64_t drawn = 0, short_passed = 0;
    // Covered pixels and whole bands' rows the coarse depth rejected (RasterContext::hz_skipped_*).
    std::uint64_t skipped = 0, skipped_rows = 0;
    for (int y = ya; y < yz;) {
      const int end = std::min(yz, (y | ((1 << HierZ::kRowsLog) - 1)) + 1);  // this band's rows
      // A new 16-row band of blocks: its tries afresh (HierZ::band_asks_afresh).
      if (kDepth && ctx_.hier_z && (y & ((1 << HierZ::kRowsLog) - 1)) == 0 &&
          HierZ::band_asks_afresh(y >> HierZ::kRowsLog, hz_rejected_))
        hz_tries_ = HierZ::kTries;
      // A band not rejected leaves the rows their tries: the band's bound is coarser than a row's.
      if (bands && hz_tries_ != 0 && !(first && (hz & kHzFirstAsked)) &&
          ctx_.hier_z->band_worth_asking(y >> HierZ::kRowsLog) &&
          ask_band(t_, clip_, st_, ctx_, zmask_, y, end - 1, hz_run_)) {
        hz_tries_ = HierZ::kTries;
        hz_rejected_ = true;
        if (!walking) walk_.start(t_, y);
        walking = true;
        skipped += walk_.count(t_, y, end - y, ctx_.counters);  // the walk goes on after the band
        skipped_rows += static_cast<std::uint64_t>(end - y);
        if (mark_from == y) mark_from = end;
        y = end;
        first = false;
        anchored = false;
        continue;
      }
      first = false;
      if (!walking) {
        walk_.start(t_, y);
        walking = true;
      }
      for (; y < end; ++y) {
        std::int64_t kl, kr;
        walk_.span_and_step(t_, y, w, kl, kr);
        if (kl > kr) {  // no sample covered: the cursor stays in its column
          if (anchored) {
            step_y<kScalar>(cur_);
            if constexpr (kLanes) ccur_.step(cy_, cden_);
          }
          continue;
        }
        if (!anchored) {
          cur_ = anchor(y, kl);
          if constexpr (kLanes) ccur_ = color_lanes(cur_.q, cur_.r);
          anchored = true;
        } else {
          move<kLanes>(kl - col_);
        }
        col_ = kl;
        if (simd_ && y + kPrefetchRows < yz) prefetch_row(y + kPrefetchRows, t_.x0 + static_cast<int>(kl), static_cast<int>(kr - kl + 1));
        const std::int64_t n = kr - kl + 1;
        drawn += static_cast<std::uint64_t>(n);
        if (n >= kMinSimdSpan && simd_ready()) {
          if (!occluded(kl, kr, y)) simd_span<kLanes>(t_.x0 + static_cast<int>(kl), y, static_cast<unsigned>(n));
          else skipped += static_cast<std::uint64_t>(n);  // the row itself was walked
        } else if constexpr (kLanes) {
          if constexpr (!kDepth) short_passed += static_cast<std::uint64_t>(n);
          ColorLanes c = ccur_;
          if constexpr (kSimple && !kDepth && !kTextured) {
            if (plain_rgba_) {  // pixel()'s store, without its per-pixel tests of the draw's constants
              std::uint8_t* p = color_ + (static_cast<std::size_t>(y) * width_ + static_cast<std::size_t>(t_.x0 + kl)) * 4;
              for (std::int64_t kx = 0; kx < n; ++kx, p += 4) {
                store_rgba(p, c.rgba());
                c.step(cx_, cden_);
              }
              continue;
            }
          }
          Steppers s = cur_;  // the planes other than colour
          for (std::int64_t kx = kl; kx <= kr; ++kx) {
            pixel(t_.x0 + static_cast<int>(kx), y, s, c.rgba());
            step_x<kScalar>(s);
            c.step(cx_, cden_);
          }
        } else {
          if constexpr (!kDepth) short_passed += static_cast<std::uint64_t>(n);
          Steppers s = cur_;
          for (std::int64_t kx = kl; kx <= kr; ++kx) {
            pixel(t_.x0 + static_cast<int>(kx), y, s, rgba_of(s));
            step_x(s);
          }
        }
      }
    }
    // Every covered pixel of the drawn rows is scanned; without depth every one passes.
    ctx_.counters.scanned += drawn;
    ctx_.counters.covered += drawn;
    ctx_.counters.passed += short_passed;
    ctx_.hz_skipped_pixels += skipped;
    ctx_.hz_skipped_rows += skipped_rows;
    return mark_from;
  }

  // The planes at (y, kx): the triangle's planes advanced y − y0 rows (exact, 128-bit) and jumped
  // kx pixels. Once per run and after a rejected band; every other row moves the cursor.
  Steppers anchor(int y, std::int64_t kx) const {
    Steppers s;
    const std::int64_t k = y - t_.y0;
    for (unsigned i = 0; i < kAttrCount; ++i) {
      if (!((kPlanes >> i) & 1)) continue;
      s.q[i] = t_.plane[i].q;
      s.r[i] = t_.plane[i].r;
      if (k > 0) Plane::advance(s.q[i], s.r[i], t_.plane[i].qy, t_.plane[i].ry, k, t_.den);
    }
    jump_x(s, kx);
    return s;
  }
  // The cursor from (y − 1, col_) to (y, col_ + d): one row and d pixels (d of either sign) in one
  // step, (qy + d·qx + f, ry + d·rx − f·den) with f = floor((ry + d·rx) / den), and one carry. A
  // straight edge moves the span's start by one of two distances a row, so the last two steps are
  // kept (steps_) and a division is paid only when the distance changes (at a vertex).
  struct CursorStep;  // below, with the cursor
  template <bool kLanes>
  void move(std::int64_t d) {
    unsigned slot = steps_[1].d == d ? 1u : 0u;
    if (steps_[slot].d != d) {  // not a kept row step (the tests of a row that hits, and no more)
      slot = victim_;
      victim_ ^= 1u;
      fill_step<kLanes>(steps_[slot], d, steps_[0].d == d - 1 || steps_[0].d == d + 1   ? &steps_[0]
                                         : steps_[1].d == d - 1 || steps_[1].d == d + 1 ? &steps_[1]
                                                                                        : nullptr);
    }
    const CursorStep& c = steps_[slot];
    if constexpr (kLanes) ccur_.step(c.c, cden_);
    for (unsigned i = 0; i < kAttrCount; ++i) {
      if (!((scalar_planes<kLanes>() >> i) & 1)) continue;
      cur_.q[i] += c.q[i];
      cur_.r[i] += c.r[i];
      const bool carry = cur_.r[i] >= t_.den;
      cur_.r[i] -= carry ? t_.den : 0;
      cur_.q[i] += carry;
    }
  }
  // c := the step of distance d. From `near` (a step of distance d ± 1, possibly c itself) it is
  // near's and one x step with one carry or borrow: an edge's two distances differ by one, so only
  // its first costs a division per plane.
  template <bool kLanes>
  [[gnu::always_inline]] void fill_step(CursorStep& c, std::int64_t d, const CursorStep* near) {
    if (near) {
      const bool right = near->d < d;
      for (unsigned i = 0; i < kAttrCount; ++i) {
        if (!((kPlanes >> i) & 1)) continue;
        const Plane& p = t_.plane[i];
        std::int64_t q = near->q[i], r = near->r[i];
        if (right) {
          r += p.rx;
          const bool carry = r >= t_.den;
          r -= carry ? t_.den : 0;
          q += p.qx + carry;
        } else {
          r -= p.rx;
          const bool borrow = r < 0;
          r += borrow ? t_.den : 0;
          q -= p.qx + borrow;
        }
        c.q[i] = q;
        c.r[i] = r;
      }
    } else {
      for (unsigned i = 0; i < kAttrCount; ++i) {
        if (!((kPlanes >> i) & 1)) continue;
        const Plane& p = t_.plane[i];
        const DivMod f = den_div_(p.ry + d * p.rx);  // |d·rx| < 2^11 · 2^36: exact in the Divider
        c.q[i] = p.qy + d * p.qx + f.q;
        c.r[i] = f.r;
      }
    }
    c.d = d;
    if constexpr (kLanes) c.c = color_lanes(c.q, c.r);
  }

  // The planes stepped as scalars: all but the colour planes when they step in lanes.
  template <bool kLanes>
  static constexpr unsigned scalar_planes() { return kLanes ? kPlanes & ~0xFu : kPlanes; }
  // The colour planes of (q, r) in lanes: quotients modulo 2^32, remainders below den < 2^30.
  static ColorLanes color_lanes(const std::int64_t* q, const std::int64_t* r) {
    ColorLanes c;
    for (unsigned i = 0; i < 4; ++i) {
      c.q[i] = static_cast<std::int32_t>(static_cast<std::uint32_t>(q[kR + i]));
      c.r[i] = static_cast<std::int32_t>(r[kR + i]);
    }
    return c;
  }
  // The lanes' x and y steps and den (run_wide<true>, once per run).
  void prepare_lanes() {
    std::int64_t q[kAttrCount], r[kAttrCount];
    for (unsigned i = 0; i < 4; ++i) {
      q[kR + i] = t_.plane[kR + i].qx;
      r[kR + i] = t_.plane[kR + i].rx;
    }
    cx_ = color_lanes(q, r);
    for (unsigned i = 0; i < 4; ++i) {
      q[kR + i] = t_.plane[kR + i].qy;
      r[kR + i] = t_.plane[kR + i].ry;
    }
    cy_ = color_lanes(q, r);
    const std::int32_t den = static_cast<std::int32_t>(t_.den);
    cden_ = i32x4{den, den, den, den};
  }
  // A pixel's Gouraud colour (pixel()) from scalar planes.
  static std::uint32_t rgba_of(const Steppers& s) {
    if constexpr (kGouraud) {
      return pack_rgba(static_cast<std::uint32_t>(s.q[kR]), static_cast<std::uint32_t>(s.q[kG]),
                       static_cast<std::uint32_t>(s.q[kB]), static_cast<std::uint32_t>(s.q[kA]));
    } else {
      return 0;
    }
  }

  template <unsigned kMask = kPlanes>
  void step_x(Steppers& s) const {
    for (unsigned i = 0; i < kAttrCount; ++i) {
      if (!((kMask >> i) & 1)) continue;
      s.q[i] += t_.plane[i].qx;
      s.r[i] += t_.plane[i].rx;
      const bool carry = s.r[i] >= t_.den;
      s.r[i] -= carry ? t_.den : 0;
      s.q[i] += carry;
    }
  }
  template <unsigned kMask = kPlanes>
  void step_y(Steppers& s) const {
    for (unsigned i = 0; i < kAttrCount; ++i) {
      if (!((kMask >> i) & 1)) continue;
      s.q[i] += t_.plane[i].qy;
      s.r[i] += t_.plane[i].ry;
      const bool carry = s.r[i] >= t_.den;
      s.r[i] -= carry ? t_.den : 0;
      s.q[i] += carry;
    }
  }
  void jump_x(Steppers& s, std::int64_t k) const {
    if (k <= 0) return;
    if (k < kStepJump) {
      for (std::int64_t j = 0; j < k; ++j) step_x(s);
      return;
    }
    for (unsigned i = 0; i < kAttrCount; ++i) {
      if (!((kPlanes >> i) & 1)) continue;
      // rx < den < 2^36 and k < 2^11: r + rx·k fits 64 bits.
      const DivMod d = den_div_(s.r[i] + t_.plane[i].rx * k);
      s.q[i] += t_.plane[i].qx * k + d.q;
      s.r[i] = d.r;
    }
  }

  // The span vector routine (and the small-triangle one, draw_narrow) applies to stores in any
  // pixel format (blend, dither and write mask included) with both buffers inside VRAM and
  // disjoint (it tests eight depths before it writes eight colours), a
  // texture inside VRAM and disjoint from both (it samples eight texels before it writes), and
  // 2·den < 2^31 so remainders fit signed
  // 32-bit lanes. Quotients are kept modulo 2^32, which is all any consumer reads (the low 32
  // bits of S, T, Q; 8 of a colour; 24 of Z).
  bool simd_ready() {
    if (!simd_checked_) {
      simd_checked_ = true;
      if (ctx_.vector) prepare_simd();
    }
    return simd_;
  }
  void prepare_simd() {
    if (!st_.color_in_vram || skip_color_) return;
    if (kDepth && (!st_.z_in_vram || !st_.buffers_disjoint)) return;
    if (kTextured && (!tex_.direct() || !texture_disjoint(st_, kDepth))) return;
    if (t_.den >= (std::int64_t{1} << 30)) return;
    simd_tpl_.den = static_cast<std::uint32_t>(t_.den);
    simd_tpl_.inv_den = 1.0 / static_cast<double>(t_.den);
    for (unsigned p = 0; p < SimdSpan::kPlanes; ++p) {
      const Plane& pl = t_.plane[kR + p];
      if (!simd_plane_used(p)) {  // zeros in every lane (simd_span writes the used planes' q0, r0 only)
        simd_tpl_.q0[p] = simd_tpl_.r0[p] = simd_tpl_.q8[p] = simd_tpl_.r8[p] = simd_tpl_.qx[p] = 0;
        for (unsigned k = 0; k < 8; ++k) simd_tpl_.qk[p][k] = simd_tpl_.rk[p][k] = 0;
        continue;
      }
      simd_tpl_.qx[p] = static_cast<std::uint32_t>(pl.qx);
      const DivMod d = den_div_(8 * pl.rx);
      const std::int64_t q8 = 8 * pl.qx + d.q;
      simd_tpl_.q8[p] = static_cast<std::uint32_t>(q8);
      simd_tpl_.r8[p] = static_cast<std::uint32_t>(d.r);
      std::int64_t qk = 0, rk = 0;  // lane k's offset: k steps from (0, 0)
      for (unsigned k = 0; k < 8; ++k) {
        simd_tpl_.qk[p][k] = static_cast<std::uint32_t>(qk);
        simd_tpl_.rk[p][k] = static_cast<std::uint32_t>(rk);
        qk += pl.qx;
        rk += pl.rx;
        if (rk >= t_.den) {
          rk -= t_.den;
          ++qk;
        }
      }
    }
    set_pixel_lanes(simd_tpl_.pixel, st_, ctx_, flat_, kGouraud, kDepth);
    if (kTextured) simd_tpl_.pixel.texture = {&tex_, &ctx_.recip, q_const_, const_rc_, st_.tex.wl, st_.tex.hl, st_.decal};
    span_fn_ = span_routine(simd_tpl_.pixel);
    simd_ = true;
  }
  static constexpr bool simd_plane_used(unsigned p) { return p < 4 ? kGouraud : p == 4 ? kDepth : kTextured; }

  // Rows two ahead are fetched while this one is drawn (random triangles miss the caches).
  void prefetch_row(int y, int x, int count) const {
    const std::size_t pix = static_cast<std::size_t>(y) * width_ + static_cast<std::size_t>(x);
    const std::size_t color_bytes = static_cast<std::size_t>(count) * st_.bpp, depth_bytes = static_cast<std::size_t>(count) * 4;
    for (std::size_t b = 0; b < color_bytes; b += 64) __builtin_prefetch(color_ + pix * st_.bpp + b, 1);
    if (kDepth)
      for (std::size_t b = 0; b < depth_bytes; b += 64) __builtin_prefetch(zbuf_ + pix * 4 + b, 1);
  }

  // Whether every pixel of row y's span kl..kr fails the depth test by the coarse bounds
  // (hier_z.hpp): its smallest depth, masked as the test masks it, is not below (LESS) or not at
  // or below (LEQUAL) the largest depth stored in the blocks it crosses. Depth is linear along the
  // row, so its smallest value over the span is at one end, and both ends are covered pixels
  // (depths within the vertices' 24-bit range). The cursor holds the planes at kl. Only with the
  // span routine (den < 2^30).
  bool occluded(std::int64_t kl, std::int64_t kr, int y) {
    if constexpr (!kDepth) {
      return false;
    } else {
      if (hz_tries_ == 0) return false;
      const Plane& p = t_.plane[kZ];
      const std::int64_t k = p.qx >= 0 ? 0 : kr - kl;  // the slope qx + rx/den has the sign of qx (0 <= rx < den)
      const std::int64_t n = cur_.r[kZ] + k * p.rx;  // 0 <= n < 2^41: exact in double
      std::int64_t f = static_cast<std::int64_t>(static_cast<double>(n) * simd_tpl_.inv_den);  // off by at most one
      f -= f * t_.den > n;
      f += (f + 1) * t_.den <= n;
      const std::int64_t z = cur_.q[kZ] + k * p.qx + f;  // the exact depth at pixel kl + k
      if (z < 0 || z > 0xFFFFFF) return false;  // not a covered depth: never rejects
      const std::uint32_t zm = static_cast<std::uint32_t>(z) & zmask_;
      if (ctx_.hier_z->occludes(zbuf_, y, t_.x0 + static_cast<int>(kl), t_.x0 + static_cast<int>(kr), zm,
                                st_.z_func == protocol::DepthFunc::Less, ctx_.hz_gen, hz_run_)) {
        hz_tries_ = HierZ::kTries;
        hz_rejected_ = true;
        return true;
      }
      --hz_tries_;
      return false;
    }
  }

  // A span whose first pixel is x (the cursor's planes).
  template <bool kLanes>
  void simd_span(int x, int y, unsigned count) {
    SimdSpan& sp = simd_tpl_;
    if constexpr (kLanes) {
      std::memcpy(sp.q0, &ccur_.q, sizeof ccur_.q);
      std::memcpy(sp.r0, &ccur_.r, sizeof ccur_.r);
    }
    // Planes the draw does not use keep the zeros prepare_simd wrote into the template.
    for (unsigned p = kLanes ? 4 : 0; p < SimdSpan::kPlanes; ++p) {
      if (!simd_plane_used(p)) continue;
      sp.q0[p] = static_cast<std::uint32_t>(cur_.q[kR + p]);
      sp.r0[p] = static_cast<std::uint32_t>(cur_.r[kR + p]);
    }
    const std::size_t pix = static_cast<std::size_t>(y) * width_ + static_cast<std::size_t>(x);
    sp.color = color_ + pix * st_.bpp;
    if (st_.dither.on && st_.fb_format != protocol::PixelFormat::RGBA8888)
      for (unsigned k = 0; k < 8; ++k) sp.bayer[k] = dither_threshold(st_.dither, x + static_cast<int>(k), y);
    sp.depth = kDepth ? zbuf_ + pix * 4 : nullptr;
    sp.count = count;
    sp.room = width_ - static_cast<unsigned>(x);
    const std::uint64_t passed = span_fn_(sp);
    ctx_.counters.passed += passed;
    if (st_.blend != protocol::BlendMode::Off) ctx_.counters.blended += passed;
    if (kTextured) textured_ += passed;
  }

  // The pixel at (x, y) with the planes s (colour, when Gouraud, as the word rgba: pack_rgba).
  [[gnu::always_inline]] void pixel(int x, int y, const Steppers& s, std::uint32_t rgba) {
    const std::size_t pix = static_cast<std::size_t>(y) * width_ + static_cast<std::size_t>(x);
    if constexpr (kDepth) {
      const std::uint32_t z = static_cast<std::uint32_t>(s.q[kZ]) & zmask_;
      std::uint8_t* zp = zbuf_ + pix * 4;
      std::uint8_t tmp[4];
      const bool direct = st_.z_in_vram;
      if (!direct) {
        if (!ctx_.mem.read(std::uint64_t{st_.fb_z} + pix * 4, tmp, 4)) ctx_.errors |= protocol::ERR_MEM_RANGE;
        zp = tmp;
      }
      if (st_.z_test && !depth_passes(st_.z_func, z, load_be32(zp) & 0xFFFFFFu)) return;
      if (st_.z_write) {
        store_be32(zp, z);
        if (!direct && !ctx_.mem.write(std::uint64_t{st_.fb_z} + pix * 4, tmp, 4)) ctx_.errors |= protocol::ERR_MEM_RANGE;
      }
    }
    if constexpr (kDepth) ++ctx_.counters.passed;  // without depth the caller counts every pixel
    if (skip_color_) return;
    if constexpr (kSimple && kGouraud && !kTextured) {
      if (st_.color_in_vram) {
        store_rgba(color_ + pix * 4, rgba);
        return;
      }
    }
    Rgba8 c = flat_;
    if constexpr (kGouraud) {
      c = {static_cast<std::uint8_t>(rgba), static_cast<std::uint8_t>(rgba >> 8), static_cast<std::uint8_t>(rgba >> 16),
           static_cast<std::uint8_t>(rgba >> 24)};
    }
    if constexpr (kTextured) {
      ++textured_;  // counted here, added to the context once per run (no per-pixel store through ctx_)
      TexelCoords tc;
      const std::uint32_t q = static_cast<std::uint32_t>(s.q[kQ]);
      if (q != 0) {
        const Reciprocal rc = q_const_ ? const_rc_ : ctx_.recip(q);
        tc = texel_coords(static_cast<std::int32_t>(s.q[kS]), static_cast<std::int32_t>(s.q[kT]), rc, st_.tex.wl,
                          st_.tex.hl);
      }
      c = combine(tex_.sample(tc, ctx_.errors), c, st_.decal);
    }
    if constexpr (kSimple) {
      if (st_.color_in_vram) {
        std::uint8_t* p = color_ + pix * 4;
        p[0] = c.r;
        p[1] = c.g;
        p[2] = c.b;
        p[3] = c.a;
        return;
      }
    }
    write_color(pix, x, y, c);
  }

  void write_color(std::size_t pix, int x, int y, Rgba8 c) {
    const unsigned bpp = st_.bpp;
    const std::uint64_t at = std::uint64_t{st_.fb_draw} + pix * bpp;
    std::uint8_t tmp[4] = {0, 0, 0, 0};
    std::uint8_t* p = color_ + pix * bpp;
    if (!st_.color_in_vram) {
      if (!ctx_.mem.read(at, tmp, bpp)) ctx_.errors |= protocol::ERR_MEM_RANGE;
      p = tmp;
    }
    if (st_.blend != protocol::BlendMode::Off) {
      ++ctx_.counters.blended;
      c = blend(st_.blend, c, protocol::load_pixel(st_.fb_format, p));
    }
    store_color(st_.fb_format, p, c, st_.dither, st_.keep_mask, x, y);
    if (!st_.color_in_vram && !ctx_.mem.write(at, tmp, bpp)) ctx_.errors |= protocol::ERR_MEM_RANGE;
  }

  const Triangle& t_;
  const DrawState& st_;
  RasterContext& ctx_;
  TextureUnit tex_;
  Divider den_div_;
  std::size_t width_ = 0;
  std::uint8_t* color_ = nullptr;
  std::uint8_t* zbuf_ = nullptr;
  std::uint32_t zmask_ = 0xFFFFFF;
  bool skip_color_ = false;
  bool plain_rgba_ = false;  // kSimple: pixel() stores the colour word straight into VRAM
  Rgba8 flat_;
  bool q_const_ = false;
  Reciprocal const_rc_;
  Divider edge_div_[3] = {Divider(1), Divider(1), Divider(1)};
  bool simd_ = false, simd_checked_ = false;
  SimdSpan simd_tpl_;  // its lane fields written by prepare_simd, not value-initialised (unused when no span is long)
  SpanRoutine span_fn_ = nullptr;  // the span routine for this draw (span_routine, by prepare_simd)
  std::uint64_t textured_ = 0;  // texture-unit pixels of this run
  std::uint32_t hz_run_ = 0;    // this run's number for the coarse depth bounds
  unsigned hz_tries_ = 0;       // rows left to ask them before giving up on this run (0: not asked)
  bool hz_rejected_ = false;    // they rejected a row of this run
  std::optional<BandClip> clip_;  // for band_occluded, when a band is asked
  // Wide rows: the edge walk, the cursor (the planes at the last drawn span's first
  // pixel, column col_) and its last two combined steps (move).
  EdgeWalk walk_;
  Steppers cur_;  // set by anchor() before it is read
  std::int64_t col_ = 0;
  // run_wide<true>: the cursor's colour planes (cur_'s are then stale), their x and y steps, den.
  ColorLanes ccur_, cx_, cy_;
  i32x4 cden_;
  struct CursorStep {
    std::int64_t d = INT64_MIN;  // the distance it moves the span's start (INT64_MIN: none yet)
    std::int64_t q[kAttrCount], r[kAttrCount];
    ColorLanes c;  // the colour planes' step in lanes (run_wide<true>)
  } steps_[2];  // the last two row steps (move)
  unsigned victim_ = 0;  // the step to replace next
};

// The rows [ya, yz) of a wide triangle: rasterize_rows's leading band tests (the triangle's
// first 16-row bands of blocks asked before a Kernel is built: a triangle whose bands are all
// rejected costs their span solves only, no Kernel set-up, plane advance or row loop). Moves ya past
// the rejected bands and says what was found in hz (Kernel::run's); false when no row is left.
bool ask_leading_bands(const Triangle& t, const DrawState& st, RasterContext& ctx, int& ya, int yz, unsigned& hz);

// Rows [ya, yz) (inside the box) with one Kernel, built once the leading band tests leave rows to
// draw. The caller has tried the small-triangle routine (draw_narrow) where it applies. A plain
// local, not std::optional: GCC zeroed the whole optional (2.2 KB, a `rep stos`) on every call,
// and the Kernel's members need no zeros (each is written before it is read).
template <bool G, bool T, bool Z, bool S>
void run_kernel(const Triangle& t, const DrawState& st, RasterContext& ctx, int ya, int yz) {
  unsigned hz = 0;
  if (!ask_leading_bands(t, st, ctx, ya, yz, hz)) return;
  Kernel<G, T, Z, S> kernel(t, st, ctx);
  kernel.run(ya, yz, hz);
}

using KernelFn = void (*)(const Triangle&, const DrawState&, RasterContext&, int, int);

// What a vector kernel drew, into the timing model's counters: `passed` pixels were blended when
// `blended` and textured (their texel reads by the filter's footprint) when `textured`.
void count_drawn(RasterContext& ctx, const DrawState& st, std::uint64_t scanned, std::uint64_t covered,
                 std::uint64_t passed, bool blended, bool textured) {
  ctx.counters.scanned += scanned;
  ctx.counters.covered += covered;
  ctx.counters.passed += passed;
  if (blended) ctx.counters.blended += passed;
  if (textured) {
    ctx.counters.textured += passed;
    ctx.counters.texel_bytes += passed * (st.tex.bilinear ? 4u : 1u) * protocol::bytes_per_pixel(st.tex.format);
  }
}

// The preview kernels' edge values at the box origin and their steps (PreviewRows, PreviewPlain).
template <class Rows>
void copy_edges(const Triangle& t, Rows& p) {
  for (int i = 0; i < 3; ++i) {
    p.e[i] = t.edge[i].e;
    p.ex[i] = t.edge[i].ex;
    p.ey[i] = t.edge[i].ey;
  }
}

// Specialisation table over the boolean axes (DuckStation-style, no JIT).
template <unsigned... I>
constexpr auto make_table(std::integer_sequence<unsigned, I...>) {
  return std::array<KernelFn, sizeof...(I)>{&run_kernel<(I & 1) != 0, (I & 2) != 0, (I & 4) != 0, (I & 8) != 0>...};
}
constexpr auto kKernels = make_table(std::make_integer_sequence<unsigned, 16>{});

// The small-triangle vector routine (narrow_simd.hpp) when its conditions hold; false otherwise.
// Inlined into rasterize_rows, its one caller (a call cost the 10-px triangles 4 % more
// instructions).
[[gnu::always_inline]] inline bool draw_narrow(const Triangle& t, const DrawState& st, RasterContext& ctx, int ya, int yz,
                                               bool gouraud, bool depth) {
  const int w = t.x1 - t.x0;
  if (w > 8 || t.x0 + 8 > static_cast<int>(st.fb_width) || !st.color_in_vram) return false;
  if (depth && (!st.z_in_vram || !st.buffers_disjoint)) return false;
  if (st.textured && (!st.tex.in_vram || !texture_disjoint(st, depth))) return false;
  if (t.den >= (std::int64_t{1} << 28)) return false;
  NarrowTriangle n;
  set_pixel_lanes(n.pixel, st, ctx, Rgba8{t.flat[0], t.flat[1], t.flat[2], t.flat[3]}, gouraud, depth);
  // Every channel masked (with a Z write, or the draw would have been dropped): the colour stage,
  // texture and blend included, does not run, as in the scalar routine.
  const std::uint8_t stored = st.fb_format == protocol::PixelFormat::RGB565 ? 0x7 : 0xF;  // RGB565 has no alpha
  const bool color_stage = (st.keep_mask & stored) != stored;
  const bool textured = st.textured && color_stage;
  std::optional<TextureUnit> unit;  // built only for textured draws (this is the 10-px hot path)
  if (textured) {
    unit.emplace(st.tex, ctx.mem);
    const bool q_const = t.plane[kQ].constant && t.plane[kQ].q != 0;  // affine: one reciprocal
    n.pixel.texture = {&*unit, &ctx.recip, q_const,
                       q_const ? ctx.recip(static_cast<std::uint32_t>(t.plane[kQ].q)) : Reciprocal{},
                       st.tex.wl, st.tex.hl, st.decal};
  }
  const std::int64_t k = ya - t.y0, rows = yz - ya;
  for (int i = 0; i < 3; ++i) {
    const Edge& e = t.edge[i];
    const std::int64_t e0 = e.e + k * e.ey;
    auto mag = [](std::int64_t v) { return v < 0 ? -v : v; };
    if (mag(e0) + 7 * mag(e.ex) + rows * mag(e.ey) >= (std::int64_t{1} << 31)) return false;
    n.e[i] = static_cast<std::int32_t>(e0);
    n.ex[i] = static_cast<std::int32_t>(e.ex);
    n.ey[i] = static_cast<std::int32_t>(e.ey);
  }
  const unsigned last = textured ? 8u : depth ? 5u : 4u;
  for (unsigned p = gouraud ? 0 : 4; p < last; ++p) {
    const Plane& pl = t.plane[kR + p];
    std::int64_t q = pl.q, r = pl.r;
    if (k > 0) Plane::advance(q, r, pl.qy, pl.ry, k, t.den);
    // Values modulo 2^32: covered pixels' attributes are exact (narrow_simd.cpp).
    n.q[p] = static_cast<std::uint32_t>(q);
    n.r[p] = static_cast<std::uint32_t>(r);
    n.qx[p] = static_cast<std::uint32_t>(pl.qx);
    n.rx[p] = static_cast<std::uint32_t>(pl.rx);
    n.qy[p] = static_cast<std::uint32_t>(pl.qy);
    n.ry[p] = static_cast<std::uint32_t>(pl.ry);
  }
  n.den = static_cast<std::uint32_t>(t.den);
  n.width = static_cast<unsigned>(w);
  n.rows = static_cast<unsigned>(rows);
  const std::size_t pix = static_cast<std::size_t>(ya) * st.fb_width + static_cast<std::size_t>(t.x0);
  n.color = ctx.mem.data() + st.fb_draw + pix * st.bpp;
  n.depth = depth ? ctx.mem.data() + st.fb_z + pix * 4 : nullptr;
  n.pitch = std::size_t{st.fb_width} * 4;
  n.color_pitch = std::size_t{st.fb_width} * st.bpp;
  if (st.dither.on && st.fb_format != protocol::PixelFormat::RGBA8888)
    for (int j = 0; j < 4; ++j)
      for (int lane = 0; lane < 8; ++lane) n.bayer[j][lane] = dither_threshold(st.dither, t.x0 + lane, ya + j);
  const NarrowCounts c = shade_narrow_simd(n);
  count_drawn(ctx, st, static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(rows), c.covered, c.passed,
              st.blend != protocol::BlendMode::Off && color_stage, textured);
  return true;
}

// The preview routine (preview_simd.hpp) for rows [ya, yz) of a triangle set up by
// setup_triangle_preview; preview_applies(st) holds.
void draw_preview(const Triangle& t, const DrawState& st, RasterContext& ctx, int ya, int yz, bool gouraud, bool depth) {
  PreviewRows p;
  p.width = t.x1 - t.x0;
  copy_edges(t, p);
  p.base = t.fplane.base;
  p.dx = t.fplane.dx;
  p.dy = t.fplane.dy;
  p.ky0 = ya - t.y0;
  p.rows = yz - ya;
  const std::size_t pix = static_cast<std::size_t>(ya) * st.fb_width + static_cast<std::size_t>(t.x0);
  p.color = ctx.mem.data() + st.fb_draw + pix * st.bpp;
  p.depth = depth ? ctx.mem.data() + st.fb_z + pix * 4 : nullptr;
  p.pitch = std::size_t{st.fb_width} * 4;
  p.color_pitch = std::size_t{st.fb_width} * st.bpp;
  p.room = st.fb_width - static_cast<unsigned>(t.x0);
  p.dither = st.dither.on && st.fb_format != protocol::PixelFormat::RGBA8888;
  if (p.dither)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 8; ++k) p.bayer[j][i][k] = dither_threshold(st.dither, t.x0 + i + k, t.y0 + j);
  const Rgba8 flat = st.gouraud ? Rgba8{t.v[0].c[0], t.v[0].c[1], t.v[0].c[2], t.v[0].c[3]}
                                : Rgba8{t.flat[0], t.flat[1], t.flat[2], t.flat[3]};
  set_pixel_lanes(p.pixel, st, ctx, flat, gouraud, depth);
  std::optional<TextureUnit> unit;  // built only for textured draws
  if (st.textured) {
    unit.emplace(st.tex, ctx.mem);
    p.pixel.texture = {&*unit, &ctx.recip, false, Reciprocal{}, st.tex.wl, st.tex.hl, st.decal};
    p.scale_u = std::ldexp(1.0f, 20 + static_cast<int>(st.tex.wl));
    p.scale_v = std::ldexp(1.0f, 20 + static_cast<int>(st.tex.hl));
  }
  const PreviewCounts c = shade_preview_simd(p);
  count_drawn(ctx, st, c.scanned, c.covered, c.passed, st.blend != protocol::BlendMode::Off, st.textured);
}

// The plain-draw preview kernel (preview_plain.hpp) for rows [ya, yz); preview_plain_applies(st).
void draw_preview_plain(const Triangle& t, const DrawState& st, RasterContext& ctx, int ya, int yz, bool depth) {
  PreviewPlain p;
  p.width = t.x1 - t.x0;
  copy_edges(t, p);
  p.planes = &t.xplane;
  p.ky0 = ya - t.y0;
  p.rows = yz - ya;
  const std::size_t pix = static_cast<std::size_t>(ya) * st.fb_width + static_cast<std::size_t>(t.x0);
  p.color = ctx.mem.data() + st.fb_draw + pix * 4;
  p.depth = depth ? ctx.mem.data() + st.fb_z + pix * 4 : nullptr;
  p.pitch = std::size_t{st.fb_width} * 4;
  p.room = st.fb_width - static_cast<unsigned>(t.x0);
  p.zmask = z_mask(ctx);
  p.z_func = st.z_test ? st.z_func : protocol::DepthFunc::Always;
  p.blend = st.blend;
  p.depth_on = depth;
  p.z_write = st.z_write;
  if (ctx.hier_z) p.bounds = {ctx.hier_z, ctx.mem.data() + st.fb_z, ctx.hz_gen, &ctx.hz_run, t.x0, t.y0};
  if (st.textured) {
    p.tex = {ctx.mem.data() + st.tex.base, &t.fplane, st.tex.wl, st.tex.hl, st.tex.wrap_s, st.tex.wrap_t,
             st.tex.bilinear, st.decal, std::ldexp(1.0f, 20 + static_cast<int>(st.tex.wl)),
             std::ldexp(1.0f, 20 + static_cast<int>(st.tex.hl))};
  }
  const PreviewCounts c = shade_preview_plain(p);
  count_drawn(ctx, st, c.scanned, c.covered, c.passed, st.blend != protocol::BlendMode::Off, st.textured);
}

}  // namespace

bool preview_applies(const DrawState& st) {
  const std::uint8_t stored = st.fb_format == protocol::PixelFormat::RGB565 ? 0x7 : 0xF;
  if (!st.color_in_vram || (st.keep_mask & stored) == stored) return false;
  const bool depth = st.z_test || st.z_write;
  if (depth && (!st.z_in_vram || !st.buffers_disjoint)) return false;
  return !st.textured || (st.tex.in_vram && texture_disjoint(st, depth));
}

SmallDraw small_draw(const DrawState& st, VideoMemory& mem, unsigned z_bits) {
  SmallDraw d;
  d.kernel = small_kernel(st);
  d.color = mem.data() + st.fb_draw;
  if (st.z_test || st.z_write) d.depth = mem.data() + st.fb_z;
  d.pitch = std::size_t{st.fb_width} * 4;
  d.width = st.fb_width;
  d.zmask = z_bits >= 24 ? 0xFFFFFFu : 0xFFFFFFu & ~((1u << (24 - z_bits)) - 1);  // z_mask
  d.z_write = st.z_write;
  d.blended = st.blend != protocol::BlendMode::Off;
  return d;
}

namespace {

bool ask_leading_bands(const Triangle& t, const DrawState& st, RasterContext& ctx, int& ya, int yz, unsigned& hz) {
  if (!ctx.hier_z || !(st.z_test || st.z_write) || !walks_rows(t)) return true;
  const std::uint32_t run = HierZ::next_run(ctx.hz_run), zmask = z_mask(ctx);
  std::optional<std::array<Divider, 3>> div;
  EdgeWalk walk;  // from row ya once a band is rejected
  std::optional<BandClip> clip;
  for (;;) {
    const int end = std::min(yz, (ya | ((1 << HierZ::kRowsLog) - 1)) + 1);
    if (!ctx.hier_z->band_worth_asking(ya >> HierZ::kRowsLog)) {
      hz |= kHzFirstAsked;  // not asked this time (HierZ::band_worth_asking): the Kernel does not ask either
      return true;
    }
    if (!ask_band(t, clip, st, ctx, zmask, ya, end - 1, run)) {
      hz |= kHzFirstAsked;
      return true;
    }
    if (!div) {
      div.emplace(std::array<Divider, 3>{edge_divider(t.edge[0]), edge_divider(t.edge[1]), edge_divider(t.edge[2])});
      walk.prepare(t, div->data());
      walk.start(t, ya);
    }
    ctx.hz_skipped_pixels += walk.count(t, ya, end - ya, ctx.counters);
    ctx.hz_skipped_rows += static_cast<std::uint64_t>(end - ya);
    hz |= kHzRejected;
    ya = end;
    if (ya >= yz) return false;
  }
}

// Gouraud only when the state asks for it and the triangle's colours differ.
bool draws_gouraud(const Triangle& t, const DrawState& st) {
  bool colors_differ = false;
  for (unsigned ch = 0; ch < 4; ++ch) colors_differ |= !t.plane[kR + ch].constant;
  return st.gouraud && colors_differ;
}

// The exact kernel for a draw (rasterize_rows).
KernelFn kernel_for(const DrawState& st, bool gouraud) {
  const bool depth = st.z_test || st.z_write;
  const unsigned key = (gouraud ? 1u : 0u) | (st.textured ? 2u : 0u) | (depth ? 4u : 0u) | (st.simple_color ? 8u : 0u);
  return kKernels[key];
}

}  // namespace

void rasterize_rows(const Triangle& t, const DrawState& st, RasterContext& ctx, int row_begin, int row_end) {
  const int ya = std::max(row_begin, t.y0);
  const int yz = std::min(row_end, t.y1);
  if (ya >= yz) return;
  const bool gouraud = draws_gouraud(t, st);
  const bool depth = st.z_test || st.z_write;
  if (t.preview) {
    if (st.preview_plain) return draw_preview_plain(t, st, ctx, ya, yz, depth);
    return draw_preview(t, st, ctx, ya, yz, gouraud, depth);
  }
  if (ctx.vector && draw_narrow(t, st, ctx, ya, yz, gouraud, depth)) return;
  kernel_for(st, gouraud)(t, st, ctx, ya, yz);
}

void observe_triangle(const Triangle& t, const DrawState& st, const PixelObserver& observer) {
  const Vertex* v = t.v;
  auto raw_edge = [](const Vertex& a, const Vertex& b, std::int64_t sx, std::int64_t sy) {
    return (std::int64_t{b.x} - a.x) * (sy - a.y) - (std::int64_t{b.y} - a.y) * (sx - a.x);
  };
  auto bias = [](const Vertex& a, const Vertex& b) -> std::int64_t {
    return (a.y == b.y && b.x > a.x) || b.y < a.y ? 0 : -1;
  };
  const std::int64_t bias0 = bias(v[1], v[2]), bias1 = bias(v[2], v[0]), bias2 = bias(v[0], v[1]);
  const long double D = static_cast<long double>(t.den / 2);
  for (int y = t.y0; y < t.y1; ++y) {
    for (int x = t.x0; x < t.x1; ++x) {
      const std::int64_t sx = 16 * std::int64_t{x} + 8, sy = 16 * std::int64_t{y} + 8;
      const std::int64_t b0 = raw_edge(v[1], v[2], sx, sy), b1 = raw_edge(v[2], v[0], sx, sy),
                         b2 = raw_edge(v[0], v[1], sx, sy);
      if (b0 + bias0 < 0 || b1 + bias1 < 0 || b2 + bias2 < 0) continue;
      auto n = [&](std::int64_t a0, std::int64_t a1, std::int64_t a2) {
        return i128{a0} * b0 + i128{a1} * b1 + i128{a2} * b2;
      };
      CoveredPixel p;
      p.x = x;
      p.y = y;
      p.triangle = t.index;
      p.z = static_cast<double>(static_cast<long double>(n(v[0].z, v[1].z, v[2].z)) / D);
      double* ch[4] = {&p.r, &p.g, &p.b, &p.a};
      for (unsigned c = 0; c < 4; ++c)
        *ch[c] = st.gouraud ? static_cast<double>(static_cast<long double>(n(v[0].c[c], v[1].c[c], v[2].c[c])) / D)
                            : t.flat[c];
      const i128 nq = n(v[0].q, v[1].q, v[2].q);
      if (nq != 0) {
        // u = S / Q with S = s / 2^24 and Q = q / 2^32: the ratio of the interpolants times 2^8.
        p.u = static_cast<double>(static_cast<long double>(n(v[0].s, v[1].s, v[2].s)) * 256 / static_cast<long double>(nq));
        p.v = static_cast<double>(static_cast<long double>(n(v[0].t, v[1].t, v[2].t)) * 256 / static_cast<long double>(nq));
      }
      observer(p);
    }
  }
}

}  // namespace gpubridge::sim
