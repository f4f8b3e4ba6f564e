// The preview's small-triangle path (backends/sim/src/preview_plain.hpp "Small triangles"): its
// own setup and the row kernel entered directly must draw the bytes the general preview path
// draws (the same planes, the same coverage), whatever rows a band split hands it; triangles it
// does not take (too big, no room for 8-word rows) and triangles that draw nothing must be
// recognised. Through the device: the same bytes for 1, 2 and 3 threads on triangles straddling
// the 16-row bands, and coverage equal to the exact path's.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "draw_state.hpp"
#include "preview_plain.hpp"
#include "rasterizer.hpp"
#include "reciprocal.hpp"
#include "setup.hpp"
#include "sim_test_util.hpp"
#include "video_memory.hpp"

namespace gpubridge::sim::test {
namespace {

constexpr unsigned kFbW = 64, kFbH = 48;
constexpr std::uint32_t kZAt = 0x10000;
constexpr std::uint64_t kVram = kZAt + std::uint64_t{kFbW} * kFbH * 4;

// A random plain, untextured state: Gouraud or flat, any depth function the plain kernel takes
// with or without the Z write, blend OFF or ALPHA, sometimes a scissor.
constexpr unsigned kFuncs[] = {1, 3, 4, 6, 7};  // LESS, LEQUAL, GREATER, GEQUAL, ALWAYS

DrawState random_state(std::mt19937& rng, bool scissored) {
  const bool z_test = rng() % 3 != 0, z_write = rng() % 2 == 0;
  const std::uint64_t mode = (rng() % 4 != 0 ? 1u : 0u) | (z_test ? 4u : 0u) | (std::uint64_t{kFuncs[rng() % 5]} << 3) |
                             (z_write ? 1u << 6 : 0u) | (rng() % 3 == 0 ? 1u << 7 : 0u);
  const std::uint64_t sc = scissored && rng() % 4 == 0 ? scissor(3 + rng() % 8, 2 + rng() % 8, kFbW - rng() % 8, kFbH - rng() % 8)
                                          : scissor(0, 0, 2047, 2047);
  const RegisterValues regs{mode, 0, 0, sc, 0, kZAt, fb_format(kFbW, kFbH, 0)};
  return decode_draw_state(regs, kVram);
}

// A vertex near (cx, cy) (1/16 pixel) within `spread` subpixels each way.
Vertex random_vertex(std::mt19937& rng, int cx, int cy, int spread) {
  Vertex v;
  v.x = cx + static_cast<int>(rng() % (2 * spread + 1)) - spread;
  v.y = cy + static_cast<int>(rng() % (2 * spread + 1)) - spread;
  v.z = rng() & 0xFFFFFF;
  for (auto& c : v.c) c = static_cast<std::uint8_t>(rng());
  return v;
}

// Random colour and depth words (the depth test passes and fails).
std::vector<std::uint8_t> random_bytes(std::uint32_t seed) {
  std::mt19937 r(seed);
  std::vector<std::uint8_t> b(kVram);
  for (auto& x : b) x = static_cast<std::uint8_t>(r());
  return b;
}

struct Drawn {
  RasterCounters counters;
  bool ok = false;
};

// Draws t through the general preview path (rasterize_rows).
Drawn draw(const Triangle& t, const DrawState& st, VideoMemory& mem, unsigned z_bits) {
  const ReciprocalUnit recip(16, 1);
  RasterContext ctx{mem, recip, z_bits, 0, {}, true};
  rasterize_rows(t, st, ctx, t.y0, t.y1);
  return {ctx.counters, true};
}

// Draws the small record t as the renderer does (rasterize_small with the state's SmallDraw), rows
// split at `split` (a band boundary; outside the box: one piece).
Drawn draw_small(const SmallTriangle& t, const DrawState& st, VideoMemory& mem, unsigned z_bits, int split) {
  const SmallDraw d = small_draw(st, mem, z_bits);
  RasterCounters c;
  rasterize_small(t, d, c, t.y0, split);
  rasterize_small(t, d, c, split, t.y1);
  return {c, true};
}

TEST(SimPreviewSmall, SameBytesAsTheRowKernel) {
  std::mt19937 rng(2411);
  const std::vector<std::uint8_t> before = random_bytes(77);
  VideoMemory m1(kVram), m2(kVram);
  unsigned drawn = 0, empty = 0, not_small = 0, covered = 0, wide = 0;
  for (int i = 0; i < 4000; ++i) {
    const unsigned z_bits = i % 5 == 0 ? 16 : 24;
    const DrawState st = random_state(rng, true);
    ASSERT_NE(st.preview_small, 0) << "a plain untextured state takes the small path";
    DrawState general = st;
    general.preview_small = 0;  // the general preview path: setup_triangle_preview, the row kernel
    // Centres anywhere on (and a little off) the framebuffer; spreads around the box-width limit
    // (8 pixels: about 128 subpixels), the 255-subpixel span limit and the former 127 one.
    const int cx = static_cast<int>(rng() % ((kFbW + 8) * 16)) - 64, cy = static_cast<int>(rng() % ((kFbH + 8) * 16)) - 64;
    const int spread = i % 6 == 0 ? 70 : i % 6 == 1 ? 40 : i % 6 == 2 ? 12 : i % 6 == 3 ? 63 : i % 6 == 4 ? 130 : 100;
    const Vertex a = random_vertex(rng, cx, cy, spread), b = random_vertex(rng, cx, cy, spread),
                 c = random_vertex(rng, cx, cy, spread);
    const unsigned subpixel_bits = i % 7 == 0 ? 2 : 4;
    SmallTriangle small;
    Triangle ref;
    const SmallSetup s = setup_small_preview(a, b, c, st, subpixel_bits, small);
    const bool ref_ok = setup_triangle_preview(a, b, c, general, subpixel_bits, false, ref);
    if (s == SmallSetup::NotSmall) {
      ++not_small;
      continue;
    }
    ASSERT_EQ(s == SmallSetup::Drawn, ref_ok) << "case " << i << ": both setups reject the same triangles";
    if (s == SmallSetup::Empty) {
      ++empty;
      continue;
    }
    ++drawn;
    wide += small.x1 - small.x0 > 8 ? 1u : 0u;
    ASSERT_NE(small.small, 0);
    ASSERT_EQ(small.x0, ref.x0);
    ASSERT_EQ(small.y0, ref.y0);
    ASSERT_EQ(small.x1, ref.x1);
    ASSERT_EQ(small.y1, ref.y1);
    std::copy(before.begin(), before.end(), m1.data());
    std::copy(before.begin(), before.end(), m2.data());
    const int split = small.y0 + static_cast<int>(rng() % static_cast<unsigned>(small.y1 - small.y0 + 1));
    const Drawn d1 = draw_small(small, st, m1, z_bits, split);
    const Drawn d2 = draw(ref, general, m2, z_bits);
    ASSERT_TRUE(std::equal(m1.data(), m1.data() + m1.size(), m2.data()))
        << "case " << i << " split at row " << split - small.y0 << " of " << small.y1 - small.y0;
    EXPECT_EQ(d1.counters.covered, d2.counters.covered) << i;
    EXPECT_EQ(d1.counters.passed, d2.counters.passed) << i;
    EXPECT_EQ(d1.counters.scanned, d2.counters.scanned) << i;
    covered += static_cast<unsigned>(d1.counters.covered);
  }
  // Every outcome occurred, and the small path drew a real number of pixels.
  EXPECT_GT(drawn, 1500u);
  EXPECT_GT(empty, 50u);
  EXPECT_GT(not_small, 200u);
  EXPECT_GT(covered, 5000u);
  EXPECT_GT(wide, 100u);  // boxes 9 to 16 wide: two groups of lanes per row
}

// Tall slivers up to the 255-subpixel span (box 8 wide, up to 16 rows): the steepest colour and Z
// planes the small setup takes, with the smallest areas, must still be the general path's bytes.
TEST(SimPreviewSmall, TallSliversSameBytesAsTheRowKernel) {
  std::mt19937 rng(2412);
  const std::vector<std::uint8_t> before = random_bytes(78);
  VideoMemory m1(kVram), m2(kVram);
  unsigned drawn = 0, tall = 0, thin = 0;
  for (int i = 0; i < 6000; ++i) {
    const DrawState st = random_state(rng, false);
    DrawState general = st;
    general.preview_small = 0;
    // a and b up to 255 subpixels apart vertically, c close to the line between them (D small).
    const int x = 16 + static_cast<int>(rng() % ((kFbW - 24) * 16)), y = static_cast<int>(rng() % ((kFbH - 17) * 16));
    const int h = 200 + static_cast<int>(rng() % 56), dx = static_cast<int>(rng() % 9) - 4;
    Vertex a = random_vertex(rng, x, y, 0), b = random_vertex(rng, x + dx, y + h, 0), c = random_vertex(rng, x, y, 0);
    const int t = static_cast<int>(rng() % static_cast<unsigned>(h + 1));
    c.x = x + dx * t / h + static_cast<int>(rng() % 5) - 2;
    c.y = y + t;
    SmallTriangle small;
    Triangle ref;
    const SmallSetup s = setup_small_preview(a, b, c, st, 4, small);
    const bool ref_ok = setup_triangle_preview(a, b, c, general, 4, false, ref);
    if (s == SmallSetup::NotSmall) continue;
    ASSERT_EQ(s == SmallSetup::Drawn, ref_ok) << "case " << i;
    if (s == SmallSetup::Empty) continue;
    ++drawn;
    tall += small.y1 - small.y0 > 8 ? 1u : 0u;
    thin += small.den < 2 * 128 ? 1u : 0u;  // D below 128: planes steeper than 2 per subpixel
    std::copy(before.begin(), before.end(), m1.data());
    std::copy(before.begin(), before.end(), m2.data());
    const int split = small.y0 + static_cast<int>(rng() % static_cast<unsigned>(small.y1 - small.y0 + 1));
    const Drawn d1 = draw_small(small, st, m1, 24, split);
    const Drawn d2 = draw(ref, general, m2, 24);
    ASSERT_TRUE(std::equal(m1.data(), m1.data() + m1.size(), m2.data())) << "case " << i;
    EXPECT_EQ(d1.counters.covered, d2.counters.covered) << i;
    EXPECT_EQ(d1.counters.passed, d2.counters.passed) << i;
  }
  EXPECT_GT(drawn, 1000u);
  EXPECT_GT(tall, 500u);
  EXPECT_GT(thin, 100u);
  std::printf("tall slivers: %u drawn, %u taller than 8 rows, %u of D < 128\n", drawn, tall, thin);
}

// The limits: a span of 255 subpixels each way with a box at most 8 wide is small, a span of 256 or
// a box 9 wide is not, nor a triangle of D = 1 spanning more than 127; a box with no room for
// 8-word rows (at the right edge) is not; a degenerate triangle and one off the framebuffer draw
// nothing; coordinates at the ends of the s12.4 range stay defined.
TEST(SimPreviewSmall, RecognisesItsTriangles) {
  std::mt19937 rng(5);
  const DrawState st = random_state(rng, false);
  auto make = [](int x, int y) {
    Vertex v;
    v.x = x;
    v.y = y;
    v.c[0] = 200;
    return v;
  };
  SmallTriangle t;
  EXPECT_EQ(setup_small_preview(make(160, 160), make(287, 160), make(160, 287), st, 4, t), SmallSetup::Drawn);
  EXPECT_EQ(t.x1 - t.x0, 8);
  EXPECT_EQ(t.y1 - t.y0, 8);
  // Sample points 16x + 8 from 168 to 280 and 296: 8 and 9 columns (9 to 16: two groups of lanes).
  EXPECT_EQ(setup_small_preview(make(160, 160), make(295, 160), make(160, 287), st, 4, t), SmallSetup::Drawn);
  EXPECT_EQ(t.x1 - t.x0, 8);
  EXPECT_EQ(setup_small_preview(make(160, 160), make(296, 160), make(160, 287), st, 4, t), SmallSetup::Drawn);
  EXPECT_EQ(t.x1 - t.x0, 9);
  // Wide: 255 subpixels (16 columns) is small, 256 is not.
  EXPECT_EQ(setup_small_preview(make(160, 160), make(415, 160), make(160, 287), st, 4, t), SmallSetup::Drawn);
  EXPECT_EQ(t.x1 - t.x0, 16);
  EXPECT_EQ(setup_small_preview(make(160, 160), make(416, 160), make(160, 287), st, 4, t), SmallSetup::NotSmall);
  // Tall: 255 subpixels (16 rows) is small, 256 is not.
  EXPECT_EQ(setup_small_preview(make(160, 160), make(287, 160), make(160, 415), st, 4, t), SmallSetup::Drawn);
  EXPECT_EQ(t.x1 - t.x0, 8);
  EXPECT_EQ(t.y1 - t.y0, 16);
  EXPECT_EQ(setup_small_preview(make(160, 160), make(287, 160), make(160, 416), st, 4, t), SmallSetup::NotSmall);
  // D = 1: small up to a span of 127, not beyond.
  EXPECT_NE(setup_small_preview(make(168, 160), make(169, 287), make(168, 161), st, 4, t), SmallSetup::NotSmall);
  EXPECT_EQ(setup_small_preview(make(168, 160), make(169, 360), make(168, 161), st, 4, t), SmallSetup::NotSmall);
  EXPECT_EQ(setup_small_preview(make(168, 160), make(169, 360), make(168, 159), st, 4, t), SmallSetup::NotSmall);  // D = −1
  // D = 2 at that span is small again.
  EXPECT_NE(setup_small_preview(make(168, 160), make(170, 360), make(168, 161), st, 4, t), SmallSetup::NotSmall);
  // One pixel: its sample point (16·10 + 8) inside, the neighbours' outside.
  EXPECT_EQ(setup_small_preview(make(164, 164), make(174, 164), make(164, 174), st, 4, t), SmallSetup::Drawn);
  EXPECT_EQ(t.x1 - t.x0, 1);
  EXPECT_EQ(t.y1 - t.y0, 1);
  // Box starting 7 pixels from the right edge: rows of 8 words would run past it.
  const int right = 16 * static_cast<int>(kFbW - 7);
  EXPECT_EQ(setup_small_preview(make(right, 16), make(right + 40, 16), make(right, 56), st, 4, t), SmallSetup::NotSmall);
  EXPECT_EQ(setup_small_preview(make(right - 16, 16), make(right + 20, 16), make(right - 16, 56), st, 4, t),
            SmallSetup::Drawn);
  // A box 9 wide needs room for 16 words: 16 pixels from the right edge, not 15.
  const int right16 = 16 * static_cast<int>(kFbW - 16);
  EXPECT_EQ(setup_small_preview(make(right16, 16), make(right16 + 140, 16), make(right16, 56), st, 4, t), SmallSetup::Drawn);
  EXPECT_EQ(t.x1 - t.x0, 9);
  EXPECT_EQ(setup_small_preview(make(right16 + 16, 16), make(right16 + 156, 16), make(right16 + 16, 56), st, 4, t),
            SmallSetup::NotSmall);
  // Degenerate (collinear) and off the framebuffer.
  EXPECT_EQ(setup_small_preview(make(100, 100), make(150, 150), make(200, 200), st, 4, t), SmallSetup::Empty);
  EXPECT_EQ(setup_small_preview(make(-32768, -32768), make(-32700, -32768), make(-32768, -32700), st, 4, t),
            SmallSetup::Empty);
  EXPECT_EQ(setup_small_preview(make(32767, 32767), make(32700, 32767), make(32767, 32700), st, 4, t),
            SmallSetup::Empty);
  // Between a pixel row's sample points: no pixel, though D != 0.
  EXPECT_EQ(setup_small_preview(make(100, 130), make(140, 130), make(100, 134), st, 4, t), SmallSetup::Empty);
}

// The small setup's instances (baseline, AVX2, AVX-512 where the CPU has them) write the same
// record: the vector instances round the Z plane in lanes (floor, then an exact split into 32-bit
// halves) where the baseline calls round_mod64 per value. Random small triangles of random depth,
// and slivers of D = 1 and 2 with far-apart depths, whose Z steps reach past 2^62 (the lanes fall
// back to the scalar there) or land on halves.
TEST(SimPreviewSmall, SetupInstancesWriteTheSameRecord) {
  std::mt19937 rng(2413);
  const SmallSetupRoutine base = small_setup_instance(0);
  ASSERT_NE(base, nullptr);
  unsigned compared = 0, thin = 0;
  for (unsigned isa = 1; isa <= 2; ++isa) {
    const SmallSetupRoutine vec = small_setup_instance(isa);
    if (!vec) continue;  // this CPU lacks the instance
    for (int i = 0; i < 20000; ++i) {
      const DrawState st = random_state(rng, i % 2 == 0);
      const bool sliver = i % 3 == 0;
      const int cx = static_cast<int>(rng() % (kFbW * 16)), cy = static_cast<int>(rng() % (kFbH * 16));
      Vertex a = random_vertex(rng, cx, cy, sliver ? 0 : 120), b = random_vertex(rng, cx, cy, sliver ? 0 : 120),
             c = random_vertex(rng, cx, cy, sliver ? 0 : 120);
      if (sliver) {  // a long thin triangle: b up to 127 away, c one or two subpixels off the line
        b.x = a.x + static_cast<int>(rng() % 128);
        b.y = a.y + static_cast<int>(rng() % 128);
        c.x = a.x + 1;
        c.y = a.y + static_cast<int>(rng() % 3);
        if (i % 2) c.z = a.z ^ 0xFFFFFF;
      }
      SmallTriangle r0{}, r1{};
      const SmallSetup s0 = base(a, b, c, st, i % 5 == 0 ? 3 : 4, r0);
      const SmallSetup s1 = vec(a, b, c, st, i % 5 == 0 ? 3 : 4, r1);
      ASSERT_EQ(s0, s1) << "isa " << isa << " case " << i;
      if (s0 != SmallSetup::Drawn) continue;
      ++compared;
      thin += r0.den <= 4 && (st.z_test || st.z_write) ? 1u : 0u;  // D of 1 or 2: the steepest Z steps
      ASSERT_EQ(r0.x0, r1.x0) << i;
      ASSERT_EQ(r0.y0, r1.y0) << i;
      ASSERT_EQ(r0.x1, r1.x1) << i;
      ASSERT_EQ(r0.y1, r1.y1) << i;
      ASSERT_EQ(r0.den, r1.den) << i;
      ASSERT_EQ(r0.small, r1.small) << i;
      for (int k = 0; k < 3; ++k) {
        ASSERT_EQ(r0.e[k], r1.e[k]) << i;
        ASSERT_EQ(r0.ex[k], r1.ex[k]) << i;
        ASSERT_EQ(r0.ey[k], r1.ey[k]) << i;
      }
      for (int ch = 0; ch < 4; ++ch) {
        ASSERT_EQ(r0.xplane.c[ch], r1.xplane.c[ch]) << i;
        ASSERT_EQ(r0.xplane.cdx[ch], r1.xplane.cdx[ch]) << i;
        ASSERT_EQ(r0.xplane.cdy[ch], r1.xplane.cdy[ch]) << i;
      }
      if (st.z_test || st.z_write) {
        ASSERT_EQ(r0.xplane.z, r1.xplane.z) << "isa " << isa << " case " << i;
        ASSERT_EQ(r0.xplane.zdx, r1.xplane.zdx) << "isa " << isa << " case " << i;
        ASSERT_EQ(r0.xplane.zdy, r1.xplane.zdy) << "isa " << isa << " case " << i;
      }
    }
  }
  if (!small_setup_instance(1)) GTEST_SKIP() << "no vector instance on this CPU";
  EXPECT_GT(compared, 10000u);
  EXPECT_GT(thin, 100u);  // with far-apart depths: Z steps past 2^62, the lanes' scalar fallback
}

// Small triangles (up to 15 pixels wide and tall) around the 16-row band boundaries of the thread
// split, in every plain state: 1, 2 and 3 threads and a second run give the same bytes; coverage
// is the exact path's; colour and Z within 1 LSB of exact (depth ALWAYS with the write: the last
// triangle wins everywhere).
TEST(SimPreviewSmall, SameBytesForAnyThreadCountAcrossBands) {
  std::mt19937 rng(16);
  constexpr unsigned kW = 96, kH = 80;
  for (int round = 0; round < 12; ++round) {
    const bool compare_exact = round % 3 == 0;
    const std::uint64_t mode = compare_exact ? 1u | 4u | (7u << 3) | (1u << 6)
                                             : (rng() % 2) | 4u | (std::uint64_t{kFuncs[rng() % 5]} << 3) | (1u << 6) |
                                                   (round % 2 ? 1u << 7 : 0u);
    const std::uint32_t seed = static_cast<std::uint32_t>(rng());
    auto render = [&](const DeviceOptions& o) {
      std::mt19937 r(seed);
      Canvas cv(kW, kH, 0, o);
      Device& d = *cv.dev;
      w(d, Reg::TRI_MODE, mode);
      w(d, Reg::PRIM, 0);
      for (int t = 0; t < 400; ++t) {
        const int band = 16 * static_cast<int>(1 + r() % 4);  // rows 16, 32, 48, 64
        const int cx = static_cast<int>(r() % (16 * kW)), cy = 16 * band + static_cast<int>(r() % 160) - 80;
        for (int k = 0; k < 3; ++k) {
          w(d, Reg::COLOR, color(static_cast<std::uint32_t>(r())));
          w(d, Reg::VERTEX, vtx(cx + static_cast<int>(r() % 241) - 120, cy + static_cast<int>(r() % 241) - 120,
                                static_cast<std::uint32_t>(r())));
        }
      }
      d.drain();
      const auto m = d.memory();
      return std::pair{std::vector<std::uint8_t>(m.begin(), m.begin() + Canvas::kZBase + kW * kH * 4),
                       d.stats().pixels_covered};
    };
    const auto one = render(preview_options(1)), two = render(preview_options(2)), three = render(preview_options(3)),
               again = render(preview_options(1));
    ASSERT_EQ(one.first, two.first) << "round " << round;
    ASSERT_EQ(one.first, three.first) << "round " << round;
    ASSERT_EQ(one.first, again.first) << "round " << round;
    const auto exact = render(DeviceOptions{});
    EXPECT_EQ(one.second, exact.second) << "round " << round;  // coverage
    EXPECT_GT(one.second, 1000u);
    if (compare_exact) {
      int max_diff = 0;
      for (std::size_t px = 0; px < std::size_t{kW} * kH; ++px) {
        for (std::size_t ch = 0; ch < 4; ++ch)
          max_diff = std::max(max_diff, std::abs(int(one.first[px * 4 + ch]) - int(exact.first[px * 4 + ch])));
        auto z = [&](const std::vector<std::uint8_t>& m) {
          const std::uint8_t* q = &m[Canvas::kZBase + px * 4];
          return (int(q[1]) << 16) | (int(q[2]) << 8) | q[3];
        };
        max_diff = std::max(max_diff, std::abs(z(one.first) - z(exact.first)));
      }
      EXPECT_LE(max_diff, 1) << "round " << round;
    }
  }
}

}  // namespace
}  // namespace gpubridge::sim::test
