#pragma once
// The preview rasteriser (`--accuracy preview`, docs/simulator.md "Preview"): the llvmpipe kind of
// pipeline. Attributes are plane equations anchored once per row at the span's first pixel (in
// double) and evaluated along it in 8 float lanes (no (q, r) stepping, no
// exact division anywhere; perspective texel coordinates from one float divide per 8 lanes), then
// converted — clamped first, so no float-to-integer conversion ever sees an out-of-range value —
// into the integer lanes of the pixel stage the exact vector routines use (pixel8.hpp: depth, texture
// fetch and filter, blend, dither, write mask, store).
//
// Coverage keeps the exact test, top-left rule included, for every coordinate the protocol allows:
// small boxes (at most 8 pixels wide) evaluate the edge functions in float lanes as
// float(E at the row's first pixel, exact in 64 bits) + k·ex, whose sign is the integer value's
// sign (docs/simulator.md proves it); wider rows find their covered span from a float estimate of
// each edge's crossing, checked and corrected against the integer edge values.
//
// Determinism: a pixel's value depends only on its (x, y) and its row's span, never on the band or
// thread that draws it (rows are evaluated from the box origin, not stepped from the band's first
// row), and the file is compiled with -ffp-contract=off, so the AVX2 and the baseline clone round
// the same operations the same way.
//
// The caller (rasterizer.cpp) guarantees: both buffers inside VRAM and disjoint, a texture inside
// VRAM disjoint from both, the colour stage not fully masked.
#include <cstddef>
#include <cstdint>

#include "pixel_lanes.hpp"

namespace gpubridge::sim {

struct PreviewRows {
  static constexpr unsigned kPlanes = 8;  // R, G, B, A, Z, S, T, Q (setup.hpp's attribute order)
  // No default member initialisers for the arrays: this is built per triangle and band, and
  // zeroing them cost 10-px triangles a tenth of their time. The caller fills what is read.
  std::int64_t e[3], ex[3], ey[3];       // biased edge values at the box origin, steps
  const double* base = nullptr;          // FloatPlanes (setup.hpp) of the triangle
  const double* dx = nullptr;
  const double* dy = nullptr;
  float scale_u = 0, scale_v = 0;        // textured: 2^(20 + log2 size), texel units of 1/4096 per S/Q
  int width = 0;                         // box width
  int ky0 = 0, rows = 0;                 // first row to draw (relative to the box origin), rows to draw
  std::uint8_t* color = nullptr;         // box origin column, first row drawn
  std::uint8_t* depth = nullptr;         // its depth word (when z_test or z_write)
  std::size_t pitch = 0, color_pitch = 0;  // bytes per depth / colour row
  unsigned room = 0;                     // pixels from the box origin column to the end of a buffer row
  bool dither = false;                   // packed format with dither: bayer[] holds the thresholds
  std::uint32_t bayer[4][4][8];          // when dither: [row % 4][first column % 4][lane] from the box origin
  PixelLanes pixel;
};

struct PreviewCounts {
  std::uint64_t scanned = 0, covered = 0, passed = 0;
};

PreviewCounts shade_preview_simd(const PreviewRows& t);

// The covered span [kl, kr] of each row of a box wider than 8 pixels, walked row by row in exact
// integers. Pixel k of a row is inside edge i when E + k·ex >= 0 (E its biased value at the row's
// first pixel). With a = |ex| and E = f·a + m (0 <= m < a, a floor division once per call): for
// ex > 0 the first covered pixel is −f, for ex < 0 the last one is f, and an edge with ex = 0
// (a = 1, f = E) covers the whole row when f >= 0. The next row adds ey = qy·a + ry: f += qy,
// m += ry and one carry, with no division per row (the previous version estimated each crossing
// in double and corrected it by integer checks: its conversions and correction loops were most of
// the time of thin triangles). Exact, so the span of a row does not depend on the row the walk
// started from (bands, threads).
class SpanWalk {
 public:
  // e, ex, ey: the biased edge values at the box origin and their steps; the walk starts at row ky.
  SpanWalk(const std::int64_t* e, const std::int64_t* ex, const std::int64_t* ey, int ky) { start(e, ex, ey, ky); }
  SpanWalk() = default;  // start() before use
  void start(const std::int64_t* e, const std::int64_t* ex, const std::int64_t* ey, int ky) {
    for (int i = 0; i < 3; ++i) {
      s_.kind[i] = ex[i] > 0 ? 1 : ex[i] < 0 ? -1 : 0;
      s_.a[i] = s_.kind[i] == 0 ? 1 : ex[i] > 0 ? ex[i] : -ex[i];
      floor_divmod(e[i] + ky * ey[i], s_.a[i], s_.f[i], s_.m[i]);
      floor_divmod(ey[i], s_.a[i], s_.qy[i], s_.ry[i]);
    }
  }
  // This row's covered span within [0, width): false when it is empty.
  [[gnu::always_inline]] bool span(int width, int& kl, int& kr) const {
    std::int64_t lo = 0, hi = width - 1;
    for (int i = 0; i < 3; ++i) {
      if (s_.kind[i] > 0) lo = -s_.f[i] > lo ? -s_.f[i] : lo;
      else if (s_.kind[i] < 0) hi = s_.f[i] < hi ? s_.f[i] : hi;
      else if (s_.f[i] < 0) return false;
    }
    if (lo > hi) return false;
    kl = static_cast<int>(lo);  // both inside [0, width) now
    kr = static_cast<int>(hi);
    return true;
  }
  // The covered pixels of the next `rows` rows (what drawing them counts as scanned and covered),
  // leaving the walk after them. A triangle's edges are two left ones and a right one, a left one
  // and two right ones, or a left, a right and a horizontal one (their ex sum to 0): the edges are
  // put in that order once, so the row loop has no branch on an edge's kind (about half the
  // instructions of span() and next_row() per row). The plain kernel counts a rejected band with
  // its own version in lanes (preview_plain_kernel.inc, count_rows: four rows at a time); this is
  // the reference it is tested against (SimPreviewBounds.LaneCountIsTheWalksCount).
  std::uint64_t count(int width, int rows) {
    int order[3];
    switch (kinds(order)) {
      case Kinds::TwoLeft: return count_as<2, 1>(order, width, rows);
      case Kinds::TwoRight: return count_as<1, 2>(order, width, rows);
      case Kinds::Horizontal: return count_as<1, 1>(order, width, rows);
      case Kinds::Other: break;
    }
    std::uint64_t n = 0;  // no other kinds for a triangle of D != 0: kept general all the same
    for (int r = 0; r < rows; ++r, next_row()) {
      int kl = 0, kr = 0;
      if (span(width, kl, kr)) n += static_cast<unsigned>(kr - kl + 1);
    }
    return n;
  }
  // The kinds of a triangle's edges (count): order[] lists the left edges (ex > 0) first, then
  // the right ones (ex < 0), then the horizontal one (ex = 0), when they are one of its three
  // kinds; Other otherwise (order[] unspecified).
  enum class Kinds { TwoLeft, TwoRight, Horizontal, Other };
  Kinds kinds(int* order) const {
    int n_left = 0, n_right = 0;
    for (int i = 0; i < 3; ++i)
      if (s_.kind[i] > 0) order[n_left++] = i;
    for (int i = 0; i < 3; ++i)
      if (s_.kind[i] < 0) order[n_left + n_right++] = i;
    for (int i = 0; i < 3; ++i)
      if (s_.kind[i] == 0) order[n_left + n_right] = i;
    if (n_left == 2 && n_right == 1) return Kinds::TwoLeft;
    if (n_left == 1 && n_right == 2) return Kinds::TwoRight;
    if (n_left == 1 && n_right == 1) return Kinds::Horizontal;
    return Kinds::Other;
  }
  // The walk's state at its row: edge i's pixel k is inside when k >= −f[i] (kind 1, ex > 0),
  // k <= f[i] (kind −1) or f[i] >= 0 (kind 0), with remainder m[i] in [0, a[i]); a row's step is
  // f += qy, m += ry and one carry. Read and written by the kernels' own count.
  struct State {
    std::int64_t f[3] = {}, m[3] = {}, a[3] = {1, 1, 1}, qy[3] = {}, ry[3] = {};
    int kind[3] = {};
  };
  State& state() { return s_; }
  // `rows` rows' step of each edge, rows·ey = q·a + r (one division per edge, once per call), for
  // advance(): the walk over rows it does not draw (rows the coarse bounds rejected) in one step
  // and a carry per edge, instead of a restart (six divisions) after them.
  struct Jump {
    std::int64_t q[3], r[3];
  };
  Jump jump(int rows) const {
    Jump j;
    for (int i = 0; i < 3; ++i) {
      const std::int64_t n = static_cast<std::int64_t>(rows) * s_.ry[i];  // below rows·a: no overflow
      j.q[i] = rows * s_.qy[i] + n / s_.a[i];
      j.r[i] = n % s_.a[i];
    }
    return j;
  }
  // The walk moved by a jump's rows: the same f and m as that many next_row() (f·a + m is the edge
  // value, and m stays in [0, a) with one carry since both remainders are below a).
  [[gnu::always_inline]] void advance(const Jump& j) {
    for (int i = 0; i < 3; ++i) {
      s_.f[i] += j.q[i];
      s_.m[i] += j.r[i];
      const bool carry = s_.m[i] >= s_.a[i];
      s_.m[i] -= carry ? s_.a[i] : 0;
      s_.f[i] += carry;
    }
  }
  [[gnu::always_inline]] void next_row() {
    for (int i = 0; i < 3; ++i) {
      s_.f[i] += s_.qy[i];
      s_.m[i] += s_.ry[i];
      const bool carry = s_.m[i] >= s_.a[i];
      s_.m[i] -= carry ? s_.a[i] : 0;
      s_.f[i] += carry;
    }
  }

 private:
  static void floor_divmod(std::int64_t n, std::int64_t d, std::int64_t& q, std::int64_t& r) {
    q = n / d;
    r = n % d;
    if (r < 0) {
      --q;
      r += d;
    }
  }
  // count() with kLeft left edges first, then kRight right ones, then (when they are 1 + 1) the
  // horizontal one, which empties every row while its value is negative.
  template <int kLeft, int kRight>
  std::uint64_t count_as(const int* order, int width, int rows) {
    std::int64_t f[3], m[3], a[3], qy[3], ry[3];
    for (int j = 0; j < 3; ++j) {
      const int i = order[j];
      f[j] = s_.f[i], m[j] = s_.m[i], a[j] = s_.a[i], qy[j] = s_.qy[i], ry[j] = s_.ry[i];
    }
    std::uint64_t n = 0;
    const std::int64_t last = width - 1;
    for (int r = 0; r < rows; ++r) {
      std::int64_t lo = 0, hi = last;
      for (int j = 0; j < kLeft; ++j) lo = -f[j] > lo ? -f[j] : lo;
      for (int j = kLeft; j < kLeft + kRight; ++j) hi = f[j] < hi ? f[j] : hi;
      if constexpr (kLeft + kRight == 2) hi = f[2] < 0 ? -1 : hi;
      n += lo <= hi ? static_cast<std::uint64_t>(hi - lo + 1) : 0u;
      for (int j = 0; j < 3; ++j) {
        f[j] += qy[j];
        m[j] += ry[j];
        const bool carry = m[j] >= a[j];
        m[j] -= carry ? a[j] : 0;
        f[j] += carry;
      }
    }
    for (int j = 0; j < 3; ++j) {
      const int i = order[j];
      s_.f[i] = f[j], s_.m[i] = m[j];
    }
    return n;
  }
  State s_;
};

}  // namespace gpubridge::sim
