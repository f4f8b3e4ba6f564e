#include "preview_simd.hpp"

#include <algorithm>

#include "pixel8.hpp"

namespace gpubridge::sim {

using protocol::PixelFormat;
using simd::i32x8;
using simd::u32x8;
typedef float f32x8 __attribute__((vector_size(32)));

namespace {

// v clamped into [lo, hi] (NaN goes to lo): the only way a float lane becomes an integer here, so
// no conversion meets a value it cannot represent. Written as maxps / minps compute (the second
// operand when the compare is false or unordered), so each bound is one instruction.
[[gnu::always_inline]] inline f32x8 clamp(f32x8 v, float lo, float hi) {
  const f32x8 l = f32x8{} + lo, h = f32x8{} + hi;
  v = v > l ? v : l;
  return v < h ? v : h;
}
// Truncation of lanes already inside [0, 2^31) or (-2^31, 2^31).
[[gnu::always_inline]] inline u32x8 to_u32(f32x8 v) { return (u32x8)__builtin_convertvector(v, i32x8); }
// floor of lanes clamped into [-2^30, 2^30].
[[gnu::always_inline]] inline u32x8 floor_u32(f32x8 v) {
  const i32x8 t = __builtin_convertvector(v, i32x8);
  return (u32x8)(t + (__builtin_convertvector(t, f32x8) > v));  // a true compare lane is −1
}

template <bool kTextured, PixelFormat kFormat, bool kNarrow>
[[gnu::always_inline]] inline PreviewCounts shade_preview(const PreviewRows& t) {
  constexpr std::size_t kBpp = protocol::bytes_per_pixel(kFormat);
  constexpr simd::Chunk kChunk = kNarrow ? simd::Chunk::Row : simd::Chunk::Span;
  const PixelLanes& px = t.pixel;
  const simd::StageFlags flags = simd::stage_flags(px);
  const i32x8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
  const f32x8 lanef = __builtin_convertvector(lane, f32x8);
  PreviewCounts counts;
  u32x8 covered = {}, passed = {};
  std::uint8_t* crow = t.color;
  std::uint8_t* zrow = t.depth;
  // Wide boxes walk their rows' spans; narrow ones test the edges in lanes.
  SpanWalk walk;
  if constexpr (!kNarrow) walk.start(t.e, t.ex, t.ey, t.ky0);
  for (int r = 0; r < t.rows; ++r, crow += t.color_pitch, zrow += flags.depth ? t.pitch : 0) {
    const int ky = t.ky0 + r;
    std::int64_t e[3];
    for (int i = 0; i < 3; ++i) e[i] = t.e[i] + ky * t.ey[i];
    int kl = 0, kr = t.width - 1;
    if constexpr (!kNarrow) {
      const bool any = walk.span(t.width, kl, kr);
      walk.next_row();
      if (!any) continue;
    }
    const unsigned count = static_cast<unsigned>(kr - kl + 1);
    counts.scanned += count;
    if constexpr (!kNarrow) {
      // Rows two ahead (about this span) are fetched while this one is drawn, as the exact span
      // routine does: random triangles miss the caches, and a depth read that waits on memory was
      // a quarter of the time of 1,000-px triangles without it.
      if (r + 2 < t.rows) {
        const std::uint8_t* c2 = crow + 2 * t.color_pitch + static_cast<std::size_t>(kl) * kBpp;
        for (std::size_t b = 0; b < count * kBpp; b += 64) __builtin_prefetch(c2 + b, 1);
        if (flags.depth) {
          const std::uint8_t* z2 = zrow + 2 * t.pitch + static_cast<std::size_t>(kl) * 4;
          for (std::size_t b = 0; b < count * 4u; b += 64) __builtin_prefetch(z2 + b, 1);
        }
      }
    }
    // The planes at the span's first pixel, from the box origin in double (not stepped from the
    // band's first row, so no thread sees other values), then float lanes along the span: each
    // lane's error is that of its offset from the anchor, not of the box's extent.
    const double kyd = ky, kld = kl;
    f32x8 rb[PreviewRows::kPlanes] = {}, dxf[PreviewRows::kPlanes] = {};  // broadcast once per row
    for (unsigned p = 0; p < PreviewRows::kPlanes; ++p) {
      if (!(px.gouraud && p < 4) && !(flags.depth && p == 4) && !(kTextured && p >= 5)) continue;
      rb[p] = f32x8{} + static_cast<float>(t.base[p] + t.dy[p] * kyd + t.dx[p] * kld);
      dxf[p] = f32x8{} + static_cast<float>(t.dx[p]);
    }
    f32x8 kx = lanef;  // lane offsets from the anchor
    u32x8 in_tri = ~u32x8{};
    if constexpr (kNarrow) {
      // Float edge lanes: float(exact E at lane 0) + k·ex keeps the integer value's sign.
      auto edge = [&](int i) __attribute__((always_inline)) { return (f32x8{} + static_cast<float>(e[i])) + lanef * static_cast<float>(t.ex[i]) >= 0.0f; };
      const i32x8 ok = edge(0) & edge(1) & edge(2);
      in_tri = (u32x8)ok;
    }
    std::uint8_t* cp = crow + static_cast<std::size_t>(kl) * kBpp;
    std::uint8_t* zp = flags.depth ? zrow + static_cast<std::size_t>(kl) * 4 : nullptr;
    for (unsigned i = 0; i < count; i += 8) {
      const unsigned n = count - i < 8 ? count - i : 8;
      const unsigned col = static_cast<unsigned>(kl) + i;
      const bool whole = kNarrow ? col + 8 <= t.room : (!kTextured && col + 8 <= t.room);
      u32x8 pass = simd::mask(lane < static_cast<std::int32_t>(n));
      if constexpr (kNarrow) pass &= in_tri;
      // Constant plane indices and bounds (not a loop from `first` to `last`): the lanes stay in
      // registers and each clamp bound is one instruction.
      u32x8 q[PreviewRows::kPlanes] = {};
      if (px.gouraud)
        for (unsigned p = 0; p < 4; ++p) q[p] = to_u32(clamp(rb[p] + dxf[p] * kx, 0.0f, 255.0f));
      if (flags.depth) q[4] = to_u32(clamp(rb[4] + dxf[4] * kx, 0.0f, 16777215.0f));
      if constexpr (kTextured) {
        // Perspective: S/Q and T/Q from one divide per 8 lanes (correctly rounded, so the same bits
        // on every CPU, unlike an rcpps estimate), in 1/4096 texel; Q <= 0 (only by rounding: Q is
        // unsigned) samples texel (0, 0) as the exact path does for Q = 0.
        const f32x8 sv = rb[5] + dxf[5] * kx, tv = rb[6] + dxf[6] * kx, qv = rb[7] + dxf[7] * kx;
        const u32x8 q_ok = (u32x8)(qv > 0.0f);
        const f32x8 inv = 1.0f / (q_ok ? qv : f32x8{} + 1.0f);
        q[5] = floor_u32(clamp(sv * (inv * t.scale_u), -0x1p30f, 0x1p30f)) & q_ok;
        q[6] = floor_u32(clamp(tv * (inv * t.scale_v), -0x1p30f, 0x1p30f)) & q_ok;
      }
      u32x8 bayer = {};
      if constexpr (kFormat != PixelFormat::RGBA8888)
        if (t.dither) bayer = simd::load8(t.bayer[ky & 3][col & 3]);
      if constexpr (kNarrow) covered -= pass;
      passed -= simd::pixel8<kTextured, kFormat, kChunk, true>(px, flags, q, pass, cp, zp, n, whole, bayer);
      kx += 8.0f;
      cp += 8 * kBpp;
      if (flags.depth) zp += 8 * 4;
    }
    if constexpr (!kNarrow) counts.covered += count;
  }
  for (unsigned k = 0; k < 8; ++k) {  // mask lanes are all ones (−1)
    counts.covered += covered[k];
    counts.passed += passed[k];
  }
  return counts;
}

}  // namespace

__attribute__((target_clones("avx2", "default"))) PreviewCounts shade_preview_simd(const PreviewRows& t) {
  const bool narrow = t.width <= 8;
  return simd::dispatch(t.pixel, [&]<bool kTextured, PixelFormat kFormat>() __attribute__((always_inline)) {
    return narrow ? shade_preview<kTextured, kFormat, true>(t) : shade_preview<kTextured, kFormat, false>(t);
  });
}


// SpanWalk::count without the walk. A row r (from the walk's row) has the pixels k with
// L(r) <= k <= R(r): L the largest of 0 and the left edges' crossings −E_i(r)/a_i, R the smallest of
// width − 1 and the right edges' E_j(r)/a_j (E = f·a + m, the walk's state), the row empty while a
// horizontal edge is negative. The walk's span is [ceil L, floor R] (ceil and floor are monotone,
// so ceil of the largest is the largest ceil), and it has floor R − ceil L + 1 pixels exactly when
// R >= L in the reals (otherwise none: floor R < ceil L). L is convex in r and R concave (a largest
// and a smallest of lines), so a line that is the largest at a run's first and last rows is the
// largest all along it (likewise the smallest), and then R − L is one line, >= 0 on rows found by
// one division: the run's count is Σ floor R(r) + Σ floor(−L(r)) + its rows, two floor sums
// (Euclid's steps). A run whose ends disagree is split where their lines cross. No rounding anywhere (the lines are
// compared cross-multiplied, in 64 bits under the bound checked first), so this is the walk's count
// for every input; the walk stays the fallback for values past that bound.
namespace {

// x(r) = (p + r·q) / d, d > 0, with r counted from the walk's row.
struct CountLine {
  std::int64_t p, q, d;
};

[[gnu::always_inline]] inline std::int64_t floor_quotient(std::int64_t n, std::int64_t d) {  // d > 0
  const std::int64_t q = n / d;
  return q - (n % d < 0);
}

// Σ_{i<n} floor((a·i + b) / m) for 0 <= a, b < m (AtCoder's floor_sum_unsigned: Euclid's steps on
// the lattice points under the line). The caller keeps m·(n + 1) below 2^64.
std::uint64_t floor_sum_unsigned(std::uint64_t n, std::uint64_t m, std::uint64_t a, std::uint64_t b) {
  std::uint64_t sum = 0;
  while (true) {
    if (a >= m) {
      sum += n * (n - 1) / 2 * (a / m);
      a %= m;
    }
    if (b >= m) {
      sum += n * (b / m);
      b %= m;
    }
    const std::uint64_t y_max = a * n + b;
    if (y_max < m) break;
    n = y_max / m;
    b = y_max % m;
    const std::uint64_t t = m;
    m = a;
    a = t;
  }
  return sum;
}

// Σ_{r=s}^{e−1} floor(x(r)) (x, s, e inside count's bound).
[[gnu::always_inline]] inline std::int64_t floor_sum(const CountLine& x, int s, int e) {
  const std::int64_t n = e - s, b = x.p + s * x.q;
  if (x.d == 1) return b * n + x.q * (n * (n - 1) / 2);
  const std::int64_t qb = floor_quotient(b, x.d), qa = floor_quotient(x.q, x.d);
  return qb * n + qa * (n * (n - 1) / 2) +
         static_cast<std::int64_t>(floor_sum_unsigned(static_cast<std::uint64_t>(n), static_cast<std::uint64_t>(x.d),
                                                      static_cast<std::uint64_t>(x.q - qa * x.d),
                                                      static_cast<std::uint64_t>(b - qb * x.d)));
}

// u(r) − v(r) has the sign of A + B·r (cross-multiplied).
struct CountCross {
  std::int64_t a, b;
};
[[gnu::always_inline]] inline CountCross cross(const CountLine& u, const CountLine& v) {
  return {u.p * v.d - v.p * u.d, u.q * v.d - v.q * u.d};
}
[[gnu::always_inline]] inline bool at_least(const CountCross& c, std::int64_t r) { return c.a + c.b * r >= 0; }

struct CountLines {
  CountLine left[4], right[4];  // the clip line (0, width − 1) first
  int n_left = 1, n_right = 1;
  // The largest left line and the smallest right one at row r (ties: either, the values are equal).
  [[gnu::always_inline]] int largest(int r) const {
    int lo = 0;
    for (int i = 1; i < n_left; ++i) lo = at_least(cross(left[lo], left[i]), r) ? lo : i;
    return lo;
  }
  [[gnu::always_inline]] int smallest(int r) const {
    int hi = 0;
    for (int j = 1; j < n_right; ++j) hi = at_least(cross(right[j], right[hi]), r) ? hi : j;
    return hi;
  }
};

// The covered pixels of rows [s, e), s < e.
std::int64_t count_run(const CountLines& t, int s, int e) {
  const int lo = t.largest(s), hi = t.smallest(s);
  if (e - s > 1) {
    // Ends that disagree: split where the last row's line overtakes the first row's (one division;
    // any split would do, the runs are counted independently, this one usually leaves two runs
    // whose ends agree where halving took four or five levels around a vertex's row).
    const int lo_e = t.largest(e - 1), hi_e = t.smallest(e - 1);
    if (lo_e != lo || hi_e != hi) {
      const CountCross g = lo_e != lo ? cross(t.left[lo_e], t.left[lo]) : cross(t.right[hi], t.right[hi_e]);
      std::int64_t mid = g.b > 0 ? -floor_quotient(g.a, g.b) : s + (e - s) / 2;  // first row with g >= 0
      mid = std::min<std::int64_t>(std::max<std::int64_t>(mid, s + 1), e - 1);
      return count_run(t, s, static_cast<int>(mid)) + count_run(t, static_cast<int>(mid), e);
    }
  }
  // One pair of lines all along [s, e): R − L >= 0 on the rows where A + B·r >= 0.
  const CountLine &left = t.left[lo], &right = t.right[hi];
  const CountCross c = cross(right, left);
  if (c.b > 0) s = static_cast<int>(std::max<std::int64_t>(s, std::min<std::int64_t>(e, -floor_quotient(c.a, c.b))));
  else if (c.b < 0) e = static_cast<int>(std::min<std::int64_t>(e, std::max<std::int64_t>(s, floor_quotient(c.a, -c.b) + 1)));
  else if (c.a < 0) return 0;
  if (s >= e) return 0;
  return floor_sum(right, s, e) + floor_sum({-left.p, -left.q, left.d}, s, e) + (e - s);
}

}  // namespace

std::uint64_t SpanWalk::count(int width, int rows) {
  // Lines in 64-bit cross-multiplications: values below 2^33 over the rows, denominators below
  // 2^29 (setup.hpp's 32-bit edges keep a box's values well inside).
  constexpr std::int64_t kValues = std::int64_t{1} << 33, kDenominators = std::int64_t{1} << 29;
  if (rows <= 0) return 0;
  if (rows >= (1 << 20)) return count_walk(width, rows);
  CountLines t;
  t.left[0] = {0, 0, 1};
  t.right[0] = {width - 1, 0, 1};
  int r0 = 0, r1 = rows;
  for (int i = 0; i < 3; ++i) {
    if (a_[i] >= kDenominators || f_[i] >= kValues || f_[i] <= -kValues || qy_[i] >= kValues / rows ||
        qy_[i] <= -kValues / rows)
      return count_walk(width, rows);
    const std::int64_t e = f_[i] * a_[i] + m_[i], ey = qy_[i] * a_[i] + ry_[i];
    const std::int64_t far = e + (rows - 1) * ey;
    if (e >= kValues || e <= -kValues || far >= kValues || far <= -kValues) return count_walk(width, rows);
    if (kind_[i] > 0) t.left[t.n_left++] = {-e, -ey, a_[i]};
    else if (kind_[i] < 0) t.right[t.n_right++] = {e, ey, a_[i]};
    else if (ey == 0) r1 = e < 0 ? r0 : r1;  // horizontal (a = 1): the rows where E >= 0
    else if (ey > 0) r0 = static_cast<int>(std::max<std::int64_t>(r0, std::min<std::int64_t>(r1, -floor_quotient(e, ey))));
    else r1 = static_cast<int>(std::min<std::int64_t>(r1, std::max<std::int64_t>(r0, floor_quotient(e, -ey) + 1)));
  }
  const std::int64_t n = r0 < r1 ? count_run(t, r0, r1) : 0;
  // Leave the walk after the rows (as count_walk does): E(r + rows) = f·a + m + rows·ey.
  for (int i = 0; i < 3; ++i) {
    m_[i] += rows * ry_[i];
    f_[i] += rows * qy_[i] + m_[i] / a_[i];
    m_[i] %= a_[i];
  }
  return static_cast<std::uint64_t>(n);
}

}  // namespace gpubridge::sim
