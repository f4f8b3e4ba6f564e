// The coarse depth bounds (hier_z.hpp) in the preview's plain kernel (preview_plain_kernel.inc,
// issue 24): a span is skipped when its smallest depth in the kernel's own arithmetic fails against
// every block it crosses, so the bytes must be those of drawing it. Checked three ways: the
// smallest depth of a span (preview_span_min_depth) against every pixel's depth computed as the
// kernel's lanes compute it, on the cases where the lanes wrap or reach past 24 bits; whole scenes
// drawn with the bounds (vector routines on) against the same preview without them
// (DeviceOptions::vector_routines off: preview draws with the same kernels, the bounds are not
// kept), at 1, 2 and 3 threads; and the ties (coplanar redraws, a constant depth equal to the
// stored one, one LSB either side, LESS against LEQUAL, z_bits 24 and 13), where a bound one LSB
// too high or a test off by its equality would reject pixels the kernel passes.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "preview_plain.hpp"
#include "preview_simd.hpp"
#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

// The depths the plain kernel computes at pixels 0..count-1 of a row whose Z lane starts at za
// and steps by zdx (modulo 2^64, as shade_wide's lanes and plane_lanes), masked as it masks them.
std::uint32_t kernel_min_depth(std::uint64_t za, std::uint64_t zdx, unsigned count, std::uint32_t zmask) {
  std::uint32_t m = 0xFFFFFFFFu;
  std::uint64_t z = za;
  for (unsigned k = 0; k < count; ++k, z += zdx) m = std::min(m, static_cast<std::uint32_t>(z >> 32) & zmask);
  return m;
}

TEST(SimPreviewBounds, SpanMinimumDepthIsTheKernelsOwn) {
  std::mt19937_64 rng(20261127);
  const std::uint32_t masks[] = {0xFFFFFFu, 0xFFFFFFu & ~((1u << 11) - 1)};  // z_bits 24 and 13
  unsigned known = 0, wrapping = 0;
  for (int i = 0; i < 200000; ++i) {
    const unsigned count = 1 + static_cast<unsigned>(rng() % (i % 4 == 0 ? 1024 : 64));
    std::uint64_t za = 0, zdx = 0;
    switch (i % 6) {
      case 0:  // ordinary: a covered depth, a slope of a few LSB per pixel either way
        za = (rng() % 0xFFFFFFull) << 32 | (rng() & 0xFFFFFFFFu);
        zdx = static_cast<std::uint64_t>(static_cast<std::int64_t>(rng() % (std::uint64_t{1} << 40)) -
                                         (std::int64_t{1} << 39));
        break;
      case 1:  // near 0: the lane goes a little negative (high word 0xFFFFFFFF)
        za = rng() % (std::uint64_t{1} << 36);
        zdx = 0 - (rng() % (std::uint64_t{1} << 34));
        break;
      case 2:  // near the top of 24 bits: the high word passes 2^24
        za = ((std::uint64_t{0xFFFFFF} << 32) - (rng() % (std::uint64_t{1} << 38)));
        zdx = rng() % (std::uint64_t{1} << 34);
        break;
      case 3:  // steep: a few pixels cross the whole range, or wrap 2^64
        za = rng();
        zdx = rng();
        break;
      case 4:  // negative lane values throughout (mod 2^64: huge)
        za = 0 - (rng() % (std::uint64_t{1} << 50));
        zdx = rng() % (std::uint64_t{1} << 30);
        break;
      default:  // flat: one depth, 1 LSB either side of a half
        za = ((rng() % 0xFFFFFFull) << 32) | (0x80000000u + (rng() % 3) - 1);
        zdx = 0;
        break;
    }
    for (const std::uint32_t zmask : masks) {
      const std::uint32_t want = kernel_min_depth(za, zdx, count, zmask);
      std::uint32_t got = 0;
      if (!preview_span_min_depth(za, zdx, count, zmask, got)) {
        ++wrapping;
        continue;
      }
      ++known;
      // Conservative (no pixel below it) and tight (some pixel at it).
      ASSERT_EQ(got, want) << "za 0x" << std::hex << za << " zdx 0x" << zdx << " count " << std::dec << count;
    }
  }
  // Both answers occur: the ordinary and flat cases are known, the wrapping ones are not.
  EXPECT_GT(known, 100000u);
  EXPECT_GT(wrapping, 50000u);
}

constexpr unsigned kWidth = 200, kHeight = 120;  // 6.25 block columns, 7.5 block rows
constexpr std::uint64_t kLess = 1 | 4 | (1u << 3) | (1u << 6), kLequal = 1 | 4 | (3u << 3) | (1u << 6);
constexpr std::uint64_t kAlways = 1 | 4 | (7u << 3) | (1u << 6);

using Scene = DrawnScene;

void triangle(Device& d, std::mt19937& rng, const int (&xy)[6], const std::uint32_t (&z)[3]) {
  w(d, Reg::PRIM, 0);
  for (int k = 0; k < 3; ++k) {
    w(d, Reg::COLOR, color(static_cast<std::uint32_t>(rng())));
    w(d, Reg::VERTEX, vtx(xy[2 * k], xy[2 * k + 1], z[k]));
  }
}

void random_triangles(Device& d, std::mt19937& rng, int count, std::uint32_t zmin, std::uint32_t zmax) {
  // Vertices up to 100 pixels from the first: boxes up to 200 wide, past kAskWidth (128), so the
  // rows that ask the bounds are drawn in runs around the rejected ones.
  std::uniform_int_distribution<int> px(-8 * 16, (kWidth + 8) * 16), py(-8 * 16, (kHeight + 8) * 16), dv(-100 * 16, 100 * 16);
  std::uniform_int_distribution<std::uint32_t> zd(zmin, zmax);
  for (int i = 0; i < count; ++i) {
    const int x = px(rng), y = py(rng);
    const bool flat = i % 3 == 0;  // one depth per triangle, as in sim_throughput --random-z
    const std::uint32_t z0 = zd(rng);
    triangle(d, rng, {x, y, x + dv(rng), y + dv(rng), x + dv(rng), y + dv(rng)},
             {z0, flat ? z0 : zd(rng), flat ? z0 : zd(rng)});
  }
}

// Near depth everywhere, random triangles behind it (the bounds reject them), the depth buffer
// raised in one part of the screen by a scissored clear, by MEM_DATA writes and by an ALWAYS draw,
// and random triangles in front of the raised parts only.
Scene random_scene(std::uint64_t mode, const DeviceOptions& o) {
  auto dev = make_device(o);
  Device& d = *dev;
  std::mt19937 rng(20261127);
  clear_target(d, kWidth, kHeight, 0xFFFFFF);
  w(d, Reg::TRI_MODE, mode);
  const int x1 = kWidth * 16, y1 = kHeight * 16;
  triangle(d, rng, {0, 0, x1, 0, 0, y1}, {0x100000, 0x100000, 0x100000});
  triangle(d, rng, {x1, y1, x1, 0, 0, y1}, {0x100000, 0x100000, 0x100000});
  random_triangles(d, rng, 150, 0x100000, 0xFFFFFF);  // behind: rejected
  random_triangles(d, rng, 50, 0x080000, 0x180000);   // partly in front
  w(d, Reg::SCISSOR, scissor(40, 20, 100, 60));
  w(d, Reg::CLEAR_DEPTH, 0xE00000);
  w(d, Reg::CLEAR_Z, 0);
  w(d, Reg::SCISSOR, scissor(0, 0, kWidth, kHeight));
  for (unsigned y = 60; y < 100; ++y) {
    w(d, Reg::MEM_ADDR, Canvas::kZBase + (y * kWidth + 100) * 4);
    for (unsigned x = 100; x < 168; x += 2) w(d, Reg::MEM_DATA, 0x00E0000000E00000ull);
  }
  w(d, Reg::TRI_MODE, kAlways);
  triangle(d, rng, {130 * 16, 0, 200 * 16, 0, 130 * 16, 40 * 16}, {0xF00000, 0xF00000, 0xF00000});
  w(d, Reg::TRI_MODE, mode);
  random_triangles(d, rng, 200, 0x180000, 0xF00000);  // in front of the raised parts only
  return finish_scene(d, kWidth, kHeight);
}

// The ties: a sloped plane and a flat one written into the depth buffer, then drawn again over
// themselves (the same vertices: the same lanes, so LESS fails and LEQUAL passes at every pixel),
// with the depth one and two LSB higher and lower, and flat triangles at the cleared depth and one
// LSB either side; planes reaching 0 and 2^24 - 1 (the lanes' ends).
Scene tie_scene(std::uint64_t mode, const DeviceOptions& o) {
  auto dev = make_device(o);
  Device& d = *dev;
  std::mt19937 rng(7);
  const std::uint32_t cleared = 0x654321;
  clear_target(d, kWidth, kHeight, cleared);
  w(d, Reg::TRI_MODE, mode);
  const int x1 = kWidth * 16, y1 = kHeight * 16;
  // The left half: sloped planes, the right half flat at the cleared depth (not drawn at first).
  const int sloped[3][6] = {{0, 0, 100 * 16, 8, 0, y1}, {100 * 16, 8, 100 * 16, y1, 0, y1},
                            {0, 0, 100 * 16, 8, 50 * 16, 60 * 16}};
  const std::uint32_t zs[3][3] = {{0x300000, 0x300100, 0x2FF000}, {0x300100, 0x301234, 0x2FF000},
                                  {0x300000, 0x300100, 0x300080}};
  for (const std::int32_t dz : {0, 0, 1, -1, 2, -2, 0}) {
    for (int i = 0; i < 2; ++i) {
      const auto z = [&](int k) { return static_cast<std::uint32_t>(static_cast<std::int32_t>(zs[i][k]) + dz); };
      triangle(d, rng, sloped[i], {z(0), z(1), z(2)});
    }
  }
  triangle(d, rng, sloped[2], {zs[2][0], zs[2][1], zs[2][2]});
  const int flat[6] = {100 * 16 + 5, 3, x1, 0, x1 - 7, y1};
  for (const std::int32_t dz : {1, 0, -1, 0, -1}) {
    const auto z = static_cast<std::uint32_t>(static_cast<std::int32_t>(cleared) + dz);
    triangle(d, rng, flat, {z, z, z});
  }
  // The depth's ends: a plane from 0 to the far end across the screen, drawn twice, and slivers
  // at 0 and at 0xFFFFFF.
  for (int i = 0; i < 2; ++i) triangle(d, rng, {0, 70 * 16, x1, 90 * 16, 0, 110 * 16}, {0, 0xFFFFFF, 0});
  triangle(d, rng, {3, 100 * 16, x1, y1, 0, y1 - 3}, {0, 0, 0});
  triangle(d, rng, {3, 100 * 16, x1, y1, 0, y1 - 3}, {0xFFFFFF, 0xFFFFFF, 0xFFFFFF});
  return finish_scene(d, kWidth, kHeight);
}

// The band test's ties (issue 24, eleventh round): boxes 16 to 127 wide, which ask the bounds band
// by band only. A grid of sloped triangles drawn and then drawn again over itself (LESS fails and
// LEQUAL passes at every pixel) one LSB and two either side, and, in block columns of their own
// (x from 96), flat triangles at the cleared depth and one LSB either side: there every block's
// bound equals the band's smallest depth, so a band bound one LSB too high rejects the LEQUAL
// redraws that pass.
Scene band_tie_scene(std::uint64_t mode, const DeviceOptions& o) {
  auto dev = make_device(o);
  Device& d = *dev;
  std::mt19937 rng(11);
  const std::uint32_t cleared = 0x456789;
  clear_target(d, kWidth, kHeight, cleared);
  w(d, Reg::TRI_MODE, mode);
  const auto cells = [&](int x0, int x1, int cw, int ch, auto&& z) {
    for (int y = 0; y < static_cast<int>(kHeight); y += ch) {
      for (int x = x0; x < x1; x += cw) {
        const int xa = x * 16, ya = y * 16, xb = std::min(x + cw, x1) * 16, yb = std::min(y + ch, static_cast<int>(kHeight)) * 16;
        triangle(d, rng, {xa, ya, xb, ya, xa, yb}, {z(xa, ya), z(xb, ya), z(xa, yb)});
        triangle(d, rng, {xb, ya, xb, yb, xa, yb}, {z(xb, ya), z(xb, yb), z(xa, yb)});
      }
    }
  };
  for (const std::int32_t dz : {0, 0, 1, -1, 2, -2, 0}) {
    cells(0, 96, 48, 40, [&](int x, int y) { return static_cast<std::uint32_t>(0x300000 + 7 * x - 5 * y + dz); });
  }
  for (const std::int32_t dz : {1, 0, -1, 0, -1}) {
    const auto z = static_cast<std::uint32_t>(static_cast<std::int32_t>(cleared) + dz);
    cells(96, static_cast<int>(kWidth), 52, 40, [&](int, int) { return z; });
  }
  return finish_scene(d, kWidth, kHeight);
}

// `passed` gets the pixels that passed the depth test without the bounds, per mode (LESS, LEQUAL)
// and z_bits (24, 13).
template <class Draw>
void same_with_and_without_bounds(Draw draw, const char* what, std::vector<std::uint64_t>& passed) {
  for (const std::uint64_t mode : {kLess, kLequal}) {
    for (const unsigned z_bits : {24u, 13u}) {
      DeviceOptions plain = preview_options(1);
      plain.vector_routines = false;  // no bounds: every span drawn
      plain.accuracy.z_bits = z_bits;
      const Scene want = draw(mode, plain);
      passed.push_back(want.stats.pixels_depth_passed);
      EXPECT_GT(want.stats.pixels_depth_passed, std::uint64_t{kWidth} * kHeight / 2) << what;
      for (const unsigned threads : {1u, 2u, 3u}) {
        DeviceOptions o = preview_options(threads);
        o.accuracy.z_bits = z_bits;
        for (int run = 0; run < 2; ++run) {
          const Scene got = draw(mode, o);
          ASSERT_EQ(got.memory, want.memory) << what << " mode 0x" << std::hex << mode << std::dec << " z_bits " << z_bits
                                             << " threads " << threads << " run " << run;
          EXPECT_TRUE(got.stats == want.stats) << what << " z_bits " << z_bits << " threads " << threads;
        }
      }
    }
  }
}

// The kernel's count of a rejected band's covered pixels (count_rows, four rows in lanes; every
// instance this CPU runs) against SpanWalk::count (the row walk) from the same start: the same
// count, and the walk left at the same row (the spans of the rows after agree). Random triangles'
// edges (the kinds the kernel sees, rows not a multiple of four), random independent edges of small
// values (any kinds, horizontal ones included: lines that meet exactly on rows and pixels), and
// wide values (remainders near the steps, large quotients).
struct CountCase {
  std::int64_t e[3], ex[3], ey[3];
  int ky, width, rows;
};

void expect_lanes_count_as_the_walk(BandCount lanes, const CountCase& c, const char* what, int index) {
  SpanWalk got(c.e, c.ex, c.ey, c.ky), want(c.e, c.ex, c.ey, c.ky);
  ASSERT_EQ(lanes(got, c.width, c.rows), want.count(c.width, c.rows)) << what << " case " << index;
  for (int r = 0; r < 5; ++r, got.next_row(), want.next_row()) {
    int kl0 = -1, kr0 = -1, kl1 = -1, kr1 = -1;
    const int w = std::max(c.width, 1);
    ASSERT_EQ(got.span(w, kl0, kr0), want.span(w, kl1, kr1)) << what << " case " << index << " after, row " << r;
    ASSERT_EQ(kl0, kl1) << what << " case " << index << " after, row " << r;
    ASSERT_EQ(kr0, kr1) << what << " case " << index << " after, row " << r;
  }
}

TEST(SimPreviewBounds, LaneCountIsTheWalksCount) {
  unsigned instances = 0;
  for (unsigned isa = 0; isa < 3; ++isa) {
    const BandCount lanes = band_count_instance(isa);
    if (!lanes) continue;
    ++instances;
    std::mt19937_64 rng(24);
    auto uniform = [&](std::int64_t lo, std::int64_t hi) { return std::uniform_int_distribution<std::int64_t>(lo, hi)(rng); };
    std::uint64_t nonzero = 0, total = 0;
    auto check = [&](const CountCase& c, const char* what, int i) {
      expect_lanes_count_as_the_walk(lanes, c, what, i);
      SpanWalk w(c.e, c.ex, c.ey, c.ky);
      const std::uint64_t n = w.count(c.width, c.rows);
      nonzero += n != 0;
      total += n;
    };
    // Triangles of random vertices (4 fractional bits), edges E = ex·x + ey·y + c from each side,
    // the box at the smallest x and y, oriented so that the inside is E >= 0 (top-left bias: −1 on
    // the edges that are not top or left, as setup.hpp biases them).
    for (int i = 0; i < 4000; ++i) {
      const int span = i % 4 == 0 ? 64 : 2048;
      std::int64_t x[3], y[3];
      for (int v = 0; v < 3; ++v) x[v] = uniform(0, span * 16), y[v] = uniform(0, span * 16);
      if (i % 5 == 1) y[1] = y[0];  // a horizontal edge
      const std::int64_t d = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
      if (d == 0) continue;
      const std::int64_t x0 = std::min({x[0], x[1], x[2]}) / 16, y0 = std::min({y[0], y[1], y[2]}) / 16;
      CountCase c{};
      for (int k = 0; k < 3; ++k) {
        const int a = (k + 1) % 3, b = (k + 2) % 3;
        std::int64_t ex = y[a] - y[b], ey = x[b] - x[a];
        if (d < 0) ex = -ex, ey = -ey;
        // E at pixel centre (x0 + 0.5, y0 + 0.5), in 1/256 units: E(p) = ex·(px − xa) + ey·(py − ya).
        const std::int64_t e = ex * (x0 * 16 + 8 - x[a]) + ey * (y0 * 16 + 8 - y[a]);
        const bool top_left = ey < 0 || (ey == 0 && ex > 0);
        c.e[k] = e - (top_left ? 0 : 1);
        c.ex[k] = ex * 16;
        c.ey[k] = ey * 16;
      }
      const int width = static_cast<int>((std::max({x[0], x[1], x[2]}) + 15) / 16 - x0) + 1;
      const int height = static_cast<int>((std::max({y[0], y[1], y[2]}) + 15) / 16 - y0) + 1;
      c.width = i % 7 == 0 ? static_cast<int>(uniform(0, width)) : width;  // clipped boxes too
      c.ky = static_cast<int>(uniform(0, height));
      c.rows = static_cast<int>(uniform(0, i % 3 == 0 ? 16 : height - c.ky));
      check(c, "triangle", i);
    }
    // Independent edges of small values: lines meeting exactly on rows and pixel columns, zero steps.
    for (int i = 0; i < 20000; ++i) {
      CountCase c{};
      for (int k = 0; k < 3; ++k) c.e[k] = uniform(-40, 40), c.ex[k] = uniform(-4, 4), c.ey[k] = uniform(-4, 4);
      c.ky = static_cast<int>(uniform(0, 8));
      c.width = static_cast<int>(uniform(0, 24));
      c.rows = static_cast<int>(uniform(0, 24));
      check(c, "small", i);
    }
    // Wide independent edges, up to the edge values of a protocol triangle.
    for (int i = 0; i < 4000; ++i) {
      CountCase c{};
      const std::int64_t limit = i % 5 == 0 ? std::int64_t{1} << 40 : std::int64_t{1} << 31;
      for (int k = 0; k < 3; ++k) {
        c.e[k] = uniform(-limit, limit);
        c.ex[k] = uniform(-limit / 2048, limit / 2048);
        c.ey[k] = uniform(-limit / 2048, limit / 2048);
      }
      c.ky = static_cast<int>(uniform(0, 2048));
      c.width = static_cast<int>(uniform(1, 2048));
      c.rows = static_cast<int>(uniform(0, 64));
      check(c, "wide", i);
    }
    // The cases drew something to count (the comparison is not of zeros).
    EXPECT_GT(nonzero, 5000u) << "instance " << isa;
    EXPECT_GT(total, 1000000u) << "instance " << isa;
  }
  EXPECT_GE(instances, 1u);
}

TEST(SimPreviewBounds, RandomDepthScenesDrawAsWithoutTheBounds) {
  std::vector<std::uint64_t> passed;
  same_with_and_without_bounds(random_scene, "random", passed);
  // The preview kernels drew the scene (Gouraud colour and Z are not the exact path's bytes).
  EXPECT_NE(random_scene(kLess, preview_options(1)).memory, random_scene(kLess, DeviceOptions{}).memory);
}

TEST(SimPreviewBounds, TiesDrawAsWithoutTheBounds) {
  std::vector<std::uint64_t> passed;
  same_with_and_without_bounds(tie_scene, "ties", passed);
  ASSERT_EQ(passed.size(), 4u);
  // The ties were there to decide: the coplanar redraws (a sloped half of the screen twice, the
  // flat one twice) pass under LEQUAL and fail under LESS.
  EXPECT_GT(passed[2], passed[0] + 3 * 100 * kHeight / 2) << "z_bits 24";
  EXPECT_GT(passed[3], passed[1] + 3 * 100 * kHeight / 2) << "z_bits 13";
}

TEST(SimPreviewBounds, BandTiesDrawAsWithoutTheBounds) {
  std::vector<std::uint64_t> passed;
  same_with_and_without_bounds(band_tie_scene, "band ties", passed);
  ASSERT_EQ(passed.size(), 4u);
  // The ties were there to decide: the coplanar grid redraw (96 columns, once) and the flat redraws
  // at the stored depth (104 columns, twice) pass under LEQUAL and fail under LESS.
  EXPECT_GT(passed[2], passed[0] + (96 + 2 * 104) * kHeight * 9 / 10) << "z_bits 24";
  EXPECT_GT(passed[3], passed[1] + (96 + 2 * 104) * kHeight * 9 / 10) << "z_bits 13";
}

}  // namespace
}  // namespace gpubridge::sim::test
