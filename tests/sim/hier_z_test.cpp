// The coarse depth bounds (backends/sim/src/hier_z.hpp) that let the exact path skip occluded
// spans: the bound itself against a depth buffer written by hand, and whole random-depth scenes
// against the reference routines (DeviceOptions::vector_routines off, which never use the bounds)
// with the depth buffer raised behind the bounds' back between draws by every path that can: MEM
// writes, a depth clear, a draw with an ALWAYS test, and the memory span. A bound that outlived
// one of them would reject spans the reference draws, and the bytes would differ.
#include <gtest/gtest.h>

#include <random>

#include "draw_state.hpp"
#include "hier_z.hpp"
#include "rasterizer.hpp"
#include "reciprocal.hpp"
#include "setup.hpp"
#include "sim_test_util.hpp"
#include "video_memory.hpp"

namespace gpubridge::sim::test {
namespace {

void put_depth(std::vector<std::uint8_t>& z, unsigned width, unsigned x, unsigned y, std::uint32_t v) {
  std::uint8_t* p = z.data() + (std::size_t{y} * width + x) * 4;
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}

TEST(SimHierZ, BlockMaximumIgnoresTheTopByteAndReadsEveryWord) {
  std::vector<std::uint8_t> z(40 * 20 * 4, 0);
  put_depth(z, 40, 5, 3, 0xFF000010);  // top byte set: the test reads 24 bits
  put_depth(z, 40, 31, 15, 0x000123);  // the block's last word
  put_depth(z, 40, 32, 0, 0x00FFFF);   // the next block
  EXPECT_EQ(depth_block_max(z.data(), 40 * 4, 16, 32), 0x123u);
  EXPECT_EQ(depth_block_max(z.data() + 32 * 4, 40 * 4, 16, 8), 0xFFFFu);
}

TEST(SimHierZ, OccludesOnlyWhatEveryStoredDepthRejects) {
  const unsigned width = 70, height = 20;  // blocks of 32 and 6 columns, 16 and 4 rows
  std::vector<std::uint8_t> z(std::size_t{width} * height * 4, 0);
  for (unsigned y = 0; y < height; ++y)
    for (unsigned x = 0; x < width; ++x) put_depth(z, width, x, y, 0x100);
  put_depth(z, width, 40, 7, 0x500);  // block (1, 0) holds a farther depth
  HierZ h;
  h.prepare(width, height);
  std::uint64_t gen = 1;
  EXPECT_TRUE(h.occludes(z.data(), 3, 0, 31, 0x100, true, gen, 1));    // LESS: equal fails
  EXPECT_FALSE(h.occludes(z.data(), 3, 0, 31, 0x100, false, gen, 1));  // LEQUAL: equal passes
  EXPECT_FALSE(h.occludes(z.data(), 3, 0, 31, 0xFF, true, gen, 1));
  EXPECT_FALSE(h.occludes(z.data(), 3, 20, 40, 0x400, true, gen, 1));  // crosses into block (1, 0)
  EXPECT_TRUE(h.occludes(z.data(), 3, 20, 40, 0x500, true, gen, 1));
  EXPECT_TRUE(h.occludes(z.data(), 17, 64, 69, 0x100, true, gen, 1));  // the partial corner block
  // Lowered by a write of run 2 (bounds only loosen): asked by run 3, the block is read again.
  for (unsigned y = 0; y < 16; ++y)
    for (unsigned x = 32; x < 64; ++x) put_depth(z, width, x, y, 0x80);
  h.mark(0, 16, 32, 63, 2);
  EXPECT_TRUE(h.occludes(z.data(), 3, 33, 40, 0x80, true, gen, 3));
  // Raised behind its back: a new generation reads the block again.
  put_depth(z, width, 10, 10, 0x900);
  EXPECT_TRUE(h.occludes(z.data(), 3, 0, 31, 0x200, true, gen, 3));  // the stale bound, same generation
  EXPECT_FALSE(h.occludes(z.data(), 3, 0, 31, 0x200, true, gen + 1, 3));
}

// The covered pixels and rows the bounds reject, counted for the band workers' measured work
// (BandSplit::measured_work): all of a triangle's behind a nearer depth buffer, none of one in front.
TEST(SimHierZ, CountsTheCoveredPixelsItRejects) {
  constexpr unsigned kW = 128, kH = 96;
  constexpr std::uint64_t kZAt = std::uint64_t{kW} * kH * 4, kVram = 2 * kZAt;
  const std::uint64_t less = 1 | 4 | (1u << 3) | (1u << 6);
  const DrawState st = decode_draw_state({less, 0, 0, scissor(0, 0, 2047, 2047), 0, kZAt, fb_format(kW, kH, 0)}, kVram);
  Vertex a, b, c;
  a.x = 4 * 16, a.y = 3 * 16;
  b.x = 120 * 16, b.y = 20 * 16;
  c.x = 30 * 16, c.y = 90 * 16;
  for (Vertex* v : {&a, &b, &c}) {
    v->z = 0x400000;
    v->c[0] = 200, v->c[3] = 255;
  }
  Triangle t;
  ASSERT_TRUE(setup_triangle(a, b, c, st, 4, false, t));
  const ReciprocalUnit recip(10, 1);
  // Stored depths nearer than the triangle everywhere, farther everywhere, and farther above row 48
  // only (the Kernel draws the top and its row loop rejects bands below: run_wide's own count).
  constexpr std::uint32_t kSplit = 1u << 24;
  for (const std::uint32_t stored : {0x000000u, 0xFFFFFFu, kSplit}) {
    VideoMemory mem(kVram);
    for (std::uint64_t i = 0; i < std::uint64_t{kW} * kH; ++i) {
      const std::uint32_t v = stored != kSplit ? stored : i / kW < 48 ? 0xFFFFFFu : 0u;
      std::uint8_t* p = mem.data() + kZAt + i * 4;
      p[1] = static_cast<std::uint8_t>(v >> 16), p[2] = static_cast<std::uint8_t>(v >> 8), p[3] = static_cast<std::uint8_t>(v);
    }
    HierZ h;
    h.prepare(kW, kH);
    RasterContext ctx{mem, recip, 24, 0, {}, true};
    ctx.hier_z = &h;
    ctx.hz_gen = 1;
    rasterize_rows(t, st, ctx, t.y0, t.y1);
    ASSERT_GT(ctx.counters.covered, 3000u);
    if (stored == 0) {
      EXPECT_EQ(ctx.counters.passed, 0u);
      EXPECT_EQ(ctx.hz_skipped_pixels, ctx.counters.covered);
      EXPECT_EQ(ctx.hz_skipped_rows, static_cast<std::uint64_t>(t.y1 - t.y0));
    } else if (stored == 0xFFFFFF) {
      EXPECT_EQ(ctx.counters.passed, ctx.counters.covered);
      EXPECT_EQ(ctx.hz_skipped_pixels, 0u);
      EXPECT_EQ(ctx.hz_skipped_rows, 0u);
    } else {  // skipped pixels failed the test; not every failing pixel need be skipped
      EXPECT_GT(ctx.counters.passed, 1000u);
      EXPECT_GT(ctx.hz_skipped_pixels, 500u);
      EXPECT_LE(ctx.hz_skipped_pixels + ctx.counters.passed, ctx.counters.covered);
      EXPECT_GE(ctx.hz_skipped_rows, 16u);
      EXPECT_LT(ctx.hz_skipped_rows, static_cast<std::uint64_t>(t.y1 - 48));
    }
  }
}

enum class Raise { MemWrites, ClearDepth, AlwaysDraw, MemorySpan };

constexpr unsigned kWidth = 200, kHeight = 120;  // 6.25 block columns, 7.5 block rows
constexpr std::uint64_t kLess = 1 | 4 | (1u << 3) | (1u << 6), kLequal = 1 | 4 | (3u << 3) | (1u << 6);

void random_triangles(Device& d, std::mt19937& rng, int count, std::uint32_t zmin, std::uint32_t zmax) {
  std::uniform_int_distribution<int> px(-8 * 16, (kWidth + 8) * 16), py(-8 * 16, (kHeight + 8) * 16), dv(-60 * 16, 60 * 16);
  std::uniform_int_distribution<std::uint32_t> zd(zmin, zmax);
  for (int i = 0; i < count; ++i) {
    const int x = px(rng), y = py(rng);
    const bool flat = i % 3 == 0;  // one depth per triangle, as in sim_throughput --random-z
    const std::uint32_t z0 = zd(rng);
    w(d, Reg::PRIM, 0);
    for (int k = 0; k < 3; ++k) {
      w(d, Reg::COLOR, color(static_cast<std::uint32_t>(rng())));
      w(d, Reg::VERTEX, vtx(k == 0 ? x : x + dv(rng), k == 0 ? y : y + dv(rng), flat ? z0 : zd(rng)));
    }
  }
}

using Scene = DrawnScene;

// Near depth everywhere, random triangles behind it (the bounds reject them), the depth buffer
// raised in part of the screen by `raise`, then random triangles again, some in front of the
// raised part only.
Scene render(Raise raise, std::uint64_t mode, const DeviceOptions& o) {
  auto dev = make_device(o);
  Device& d = *dev;
  std::mt19937 rng(20261127);
  clear_target(d, kWidth, kHeight, 0xFFFFFF);
  w(d, Reg::TRI_MODE, mode);
  w(d, Reg::PRIM, 0);
  const int x1 = kWidth * 16, y1 = kHeight * 16;
  for (const auto v : {vtx(0, 0, 0x100000), vtx(x1, 0, 0x100000), vtx(0, y1, 0x100000), vtx(x1, y1, 0x100000),
                       vtx(x1, 0, 0x100000), vtx(0, y1, 0x100000)}) {
    w(d, Reg::COLOR, color(0x20406080));
    w(d, Reg::VERTEX, v);
  }
  random_triangles(d, rng, 150, 0x100000, 0xFFFFFF);  // behind: rejected
  random_triangles(d, rng, 50, 0x080000, 0x180000);   // partly in front
  // Raise rows 20..99, columns 40..167 to 0xE00000 (or the far end).
  switch (raise) {
    case Raise::MemWrites:
      for (unsigned y = 20; y < 100; ++y) {
        w(d, Reg::MEM_ADDR, Canvas::kZBase + (y * kWidth + 40) * 4);
        for (unsigned x = 40; x < 168; x += 2) w(d, Reg::MEM_DATA, 0x00E0000000E00000ull);
      }
      break;
    case Raise::ClearDepth:
      w(d, Reg::SCISSOR, scissor(40, 20, 168, 100));
      w(d, Reg::CLEAR_DEPTH, 0xE00000);
      w(d, Reg::CLEAR_Z, 0);
      w(d, Reg::SCISSOR, scissor(0, 0, kWidth, kHeight));
      break;
    case Raise::AlwaysDraw:
      w(d, Reg::TRI_MODE, (mode & ~std::uint64_t{0x38}) | (7u << 3));
      w(d, Reg::PRIM, 0);
      for (const auto v : {vtx(40 * 16, 20 * 16, 0xE00000), vtx(168 * 16, 20 * 16, 0xE00000), vtx(40 * 16, 100 * 16, 0xE00000),
                           vtx(168 * 16, 100 * 16, 0xE00000), vtx(168 * 16, 20 * 16, 0xE00000), vtx(40 * 16, 100 * 16, 0xE00000)}) {
        w(d, Reg::COLOR, color(0x80808080));
        w(d, Reg::VERTEX, v);
      }
      w(d, Reg::TRI_MODE, mode);
      break;
    case Raise::MemorySpan: {
      auto m = d.memory();
      for (unsigned y = 20; y < 100; ++y)
        for (unsigned x = 40; x < 168; ++x) {
          std::uint8_t* p = m.data() + Canvas::kZBase + (y * kWidth + x) * 4;
          p[0] = 0, p[1] = 0xE0, p[2] = 0, p[3] = 0;
        }
      break;
    }
  }
  random_triangles(d, rng, 200, 0x180000, 0xF00000);  // in front of the raised part only
  return finish_scene(d, kWidth, kHeight);
}

TEST(SimHierZ, RaisedDepthBufferDrawsAsTheReferenceRoutines) {
  for (const Raise raise : {Raise::MemWrites, Raise::ClearDepth, Raise::AlwaysDraw, Raise::MemorySpan}) {
    for (const std::uint64_t mode : {kLess, kLequal}) {
      for (const unsigned z_bits : {24u, 13u}) {
        DeviceOptions ref;
        ref.vector_routines = false;
        ref.accuracy.z_bits = z_bits;
        const Scene want = render(raise, mode, ref);
        // Triangles behind the near depth drew nothing; in front of the raised part, many pixels.
        ASSERT_GT(want.stats.pixels_depth_passed, std::uint64_t{kWidth} * kHeight + 20000) << static_cast<int>(raise);
        for (const unsigned threads : {1u, 2u, 3u}) {
          DeviceOptions o;
          o.threads = threads;
          o.accuracy.z_bits = z_bits;
          const Scene got = render(raise, mode, o);
          ASSERT_EQ(got.memory, want.memory) << "raise " << static_cast<int>(raise) << " mode " << mode << " z_bits "
                                             << z_bits << " threads " << threads;
          EXPECT_TRUE(got.stats == want.stats) << "raise " << static_cast<int>(raise) << " threads " << threads;
        }
      }
    }
  }
}


// Large triangles whose depth slopes from just in front of a flat depth buffer at one corner to
// far behind it at the others: the bands the front corner lies in must be drawn, the rest may be
// skipped (the band test's bound is the least depth of the triangle's part between the band's
// sample rows). Vertices on pixel centres with a depth equal to the stored one (drawn under
// LEQUAL, not under LESS), or one below it; tall and wide slivers; some clipped by the scissor.
Scene render_sloped(std::uint64_t mode, const DeviceOptions& o) {
  auto dev = make_device(o);
  Device& d = *dev;
  std::mt19937 rng(20261128);
  constexpr std::uint32_t kStored = 0x400000;
  clear_target(d, kWidth, kHeight, kStored);
  w(d, Reg::TRI_MODE, mode);
  std::uniform_int_distribution<int> px(-20, kWidth + 20), py(-20, kHeight + 20), dv(-90, 90), sub(0, 15), pick(0, 3);
  for (int i = 0; i < 400; ++i) {
    if (i % 50 == 0) w(d, Reg::SCISSOR, i % 100 == 0 ? scissor(0, 0, kWidth, kHeight) : scissor(13, 7, 181, 109));
    const int x = px(rng), y = py(rng);
    const int p = pick(rng);
    // The front vertex on a pixel centre (p 0, 1) or anywhere inside a pixel (p 2, 3).
    const int fx = 16 * x + (p < 2 ? 8 : sub(rng)), fy = 16 * y + (p < 2 ? 8 : sub(rng));
    const std::uint32_t fz = p == 0 ? kStored : p == 1 ? kStored - 1 : kStored - 1 - static_cast<std::uint32_t>(sub(rng)) * 0x8000;
    int wide = dv(rng), tall = dv(rng);
    if (i % 7 == 0) wide /= 30;  // a tall sliver
    if (i % 7 == 1) tall /= 30;  // a wide one
    w(d, Reg::PRIM, 0);
    w(d, Reg::COLOR, color(static_cast<std::uint32_t>(rng())));
    w(d, Reg::VERTEX, vtx(fx, fy, fz));
    w(d, Reg::COLOR, color(static_cast<std::uint32_t>(rng())));
    w(d, Reg::VERTEX, vtx(fx + 16 * wide, fy + 16 * dv(rng), 0xF00000 + static_cast<std::uint32_t>(sub(rng))));
    w(d, Reg::COLOR, color(static_cast<std::uint32_t>(rng())));
    w(d, Reg::VERTEX, vtx(fx + 16 * dv(rng), fy + 16 * tall, kStored + 0x10000 * static_cast<std::uint32_t>(sub(rng))));
  }
  return finish_scene(d, kWidth, kHeight);
}

TEST(SimHierZ, SlopedTrianglesBarelyInFrontDrawAsTheReferenceRoutines) {
  for (const std::uint64_t mode : {kLess, kLequal}) {
    for (const unsigned z_bits : {24u, 13u}) {
      DeviceOptions ref;
      ref.vector_routines = false;
      ref.accuracy.z_bits = z_bits;
      const Scene want = render_sloped(mode, ref);
      // Most covered pixels are behind the stored depth; some in front.
      ASSERT_GT(want.stats.pixels_depth_passed, 200u);
      ASSERT_GT(want.stats.pixels_covered, 20 * want.stats.pixels_depth_passed);
      for (const unsigned threads : {1u, 2u, 3u}) {
        DeviceOptions o;
        o.threads = threads;
        o.accuracy.z_bits = z_bits;
        const Scene got = render_sloped(mode, o);
        ASSERT_EQ(got.memory, want.memory) << "mode " << mode << " z_bits " << z_bits << " threads " << threads;
        EXPECT_TRUE(got.stats == want.stats) << "mode " << mode << " z_bits " << z_bits << " threads " << threads;
      }
    }
  }
}

}  // namespace
}  // namespace gpubridge::sim::test
