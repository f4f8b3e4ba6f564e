// The SDRAM row model of the timing model (docs/protocol.md section 19, timing.hpp SdramRows):
// row hits, opens and misses on hand-made access streams, the span stream of the ecp5 memory
// port against a literal access-by-access replay, the device's counts of a drawn triangle, and
// what the row and refresh terms add to an estimate; the texel cache's reads in the stream.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "gpubridge/sim/timing.hpp"
#include "reference.hpp"
#include "sdram_spans.hpp"
#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

using Outcome = SdramRows::Outcome;

struct Counts {
  std::uint64_t hits, opens, misses;
  bool operator==(const Counts&) const = default;
};
Counts counts(const SdramRows& r) { return {r.hits(), r.opens(), r.misses()}; }
std::ostream& operator<<(std::ostream& os, const Counts& c) {
  return os << "{hits " << c.hits << ", opens " << c.opens << ", misses " << c.misses << "}";
}

TEST(SimSdramRows, HitOpenMissAndRefresh) {
  SdramRows r;  // 1 KiB rows, 4 banks: bank = address bits 10..11, row = bits 12 and up
  EXPECT_EQ(r.access(0x0000), Outcome::Open);   // bank 0 idle: ACTIVE
  EXPECT_EQ(r.access(0x03FC), Outcome::Hit);    // same 1 KiB row
  EXPECT_EQ(r.access(0x0400), Outcome::Open);   // next KiB: bank 1, idle
  EXPECT_EQ(r.access(0x1000), Outcome::Miss);   // bank 0, another row: PRECHARGE + ACTIVE
  EXPECT_EQ(r.access(0x0404), Outcome::Hit);    // bank 1 kept its row meanwhile
  EXPECT_EQ(r.access(0x0000), Outcome::Miss);   // bank 0 back to row 0
  EXPECT_EQ(counts(r), (Counts{2, 2, 2}));
  r.refresh();                                  // every bank precharged
  EXPECT_EQ(r.access(0x0000), Outcome::Open);   // not a miss: nothing to precharge
  EXPECT_EQ(r.access(0x0400), Outcome::Open);
  EXPECT_EQ(r.access(0x0000, 5), Outcome::Hit); // a run of 5 in the open row: 5 hits
  EXPECT_EQ(counts(r), (Counts{7, 4, 2}));
  r.touch(0x2000);                              // bank 0 row 2, uncounted
  EXPECT_EQ(counts(r), (Counts{7, 4, 2}));
  EXPECT_EQ(r.access(0x2010), Outcome::Hit);
  r.touch_range(0x3F00, 0x200);                 // bank 3 row 3, then bank 0 row 4
  EXPECT_EQ(r.access(0x3FF0), Outcome::Hit);
  EXPECT_EQ(r.access(0x4000), Outcome::Hit);
  EXPECT_EQ(r.access(0x2000), Outcome::Miss);
  r.reset_counts();
  EXPECT_EQ(counts(r), (Counts{0, 0, 0}));
}

TEST(SimSdramRows, GeometryIsAParameter) {
  SdramRows r(SdramGeometry{9, 1});  // 512-byte rows, 2 banks
  EXPECT_EQ(r.access(0x000), Outcome::Open);
  EXPECT_EQ(r.access(0x200), Outcome::Open);  // bank 1
  EXPECT_EQ(r.access(0x400), Outcome::Miss);  // bank 0 again, row 2
}

// The memory port's order, one access at a time: per pixel its depth read and write, then, after
// the last pixel of a colour word, the word's read and write (the write combiner).
Counts literal_span(const SpanAccess& s) {
  SdramRows r;
  for (unsigned i = 0; i < s.pixels; ++i) {
    const std::uint64_t z = s.depth + 4ull * i;
    if (s.z_read) r.access(z);
    if (s.z_write) r.access(z);
    const std::uint64_t word = (s.color + std::uint64_t{s.bpp} * i) >> 2;
    const bool last = i + 1 == s.pixels || ((s.color + std::uint64_t{s.bpp} * (i + 1)) >> 2) != word;
    if (!last) continue;
    if (s.color_read) r.access(word * 4);
    if (s.color_write) r.access(word * 4);
  }
  return counts(r);
}
Counts span_counts(const SpanAccess& s) {
  SdramRows r;
  access_span(r, s);
  return counts(r);
}

TEST(SimSdramRows, SpanInOneBankMissesAtEverySwitch) {
  // colour at bank 0 row 0, depth at bank 0 row 4: Z Z C per RGBA8888 pixel
  SpanAccess s{0x0000, 0x4000, 4, 4, true, true, false, true};
  // Z (open) Z (hit) C (miss) Z (miss) Z C (miss) ...: 1 open, 7 misses, 4 hits
  EXPECT_EQ(span_counts(s), (Counts{4, 1, 7}));
  // RGB565: a colour word every two pixels: ZZZZ C ZZZZ C
  s.bpp = 2;
  EXPECT_EQ(span_counts(s), (Counts{6, 1, 3}));
  // depth in bank 1: each bank keeps its row: 2 opens, the rest hits
  s.bpp = 4;
  s.depth = 0x4400;
  EXPECT_EQ(span_counts(s), (Counts{10, 2, 0}));
  // a colour-only span across a row boundary: words 254, 255 (bank 0), 256, 257 (bank 1)
  EXPECT_EQ(span_counts(SpanAccess{1016, 0, 4, 4, false, false, false, true}), (Counts{2, 2, 0}));
}

TEST(SimSdramRows, SpanRunsMatchALiteralReplay) {
  std::mt19937 rng(19);
  for (int n = 0; n < 4000; ++n) {
    SpanAccess s;
    s.bpp = std::array<unsigned, 3>{1, 2, 4}[rng() % 3];
    s.color = (rng() % 0x8000) * s.bpp;
    s.depth = (rng() % 0x8000) * 4;
    s.pixels = 1 + rng() % 700;
    s.z_read = rng() & 1;
    s.z_write = rng() & 1;
    s.color_read = rng() & 1;
    s.color_write = rng() & 1;
    ASSERT_EQ(span_counts(s), literal_span(s)) << "span " << n << ": colour " << s.color << " bpp " << s.bpp
                                               << " depth " << s.depth << " pixels " << s.pixels;
  }
}

constexpr unsigned kZTest = 4, kZWrite = 64;
constexpr unsigned kLess = 1 << 3;

// The device's row counts of one Z-tested triangle against the literal replay of its covered
// pixels (reference coverage), for a depth buffer in the colour buffer's banks and beside them.
TEST(SimSdramRows, DeviceCountsTheDrawnSpans) {
  const ref::P a{2 * 16, 3 * 16}, b{60 * 16, 5 * 16}, c{9 * 16, 40 * 16};
  for (std::uint32_t zbase : {0x100000u, 0x100400u}) {
    DeviceOptions counting;
    counting.sdram_rows = true;
    Canvas cv(64, 48, 0, counting);
    w(*cv.dev, Reg::FB_Z, zbase);
    w(*cv.dev, Reg::TRI_MODE, kZTest | kLess | kZWrite);
    cv.dev->reset_stats();
    cv.tri(int(a.x), int(a.y), int(b.x), int(b.y), int(c.x), int(c.y), 0xFFFFFFFF, 0xFFFFFFFF, 0xFFFFFFFF, 100, 100, 100);
    const DeviceStats& st = cv.dev->stats();
    // the rows the clears left open, then every covered span in order
    SdramRows r;
    r.touch_range(0, 64 * 48 * 4);
    r.touch_range(0x100000, 64 * 48 * 4);
    r.reset_counts();
    std::uint64_t covered = 0;
    for (int y = 0; y < 48; ++y) {
      int x0 = -1, x1 = -1;
      for (int x = 0; x < 64; ++x)
        if (ref::sample(a, b, c, x, y).covered) {
          if (x0 < 0) x0 = x;
          x1 = x;
        }
      if (x0 < 0) continue;
      covered += static_cast<std::uint64_t>(x1 - x0 + 1);
      for (int x = x0; x <= x1; ++x) {
        const std::uint64_t p = std::uint64_t(y) * 64 + std::uint64_t(x);
        r.access(zbase + 4 * p);
        r.access(zbase + 4 * p);
        r.access(4 * p);
      }
    }
    ASSERT_EQ(st.pixels_covered, covered);
    EXPECT_EQ(st.sdram_accesses, r.hits() + r.opens() + r.misses());
    EXPECT_EQ(st.sdram_accesses, 3 * covered);
    EXPECT_EQ(st.row_opens, r.opens()) << std::hex << zbase;
    EXPECT_EQ(st.row_misses, r.misses()) << std::hex << zbase;
    if (zbase == 0x100000u) EXPECT_GT(st.row_misses, covered) << "same bank: misses at every switch";
    else EXPECT_LT(st.row_misses, covered / 8) << "other bank: misses only where rows change";
  }
}

// The count costs a span replay per triangle: a device not asked for it (the default) leaves the
// counters at 0 and draws the same bytes.
TEST(SimSdramRows, CountedOnlyWhenAskedFor) {
  DeviceOptions counting;
  counting.sdram_rows = true;
  Canvas plain(64, 48), counted(64, 48, 0, counting);
  for (Canvas* cv : {&plain, &counted}) {
    w(*cv->dev, Reg::TRI_MODE, kZTest | kLess | kZWrite);
    cv->dev->reset_stats();
    cv->tri(2 * 16, 3 * 16, 60 * 16, 5 * 16, 9 * 16, 40 * 16, 0xFFFFFFFF, 0xFFFFFFFF, 0xFFFFFFFF, 100, 100, 100);
  }
  EXPECT_EQ(plain.dev->stats().sdram_accesses, 0u);
  EXPECT_EQ(plain.dev->stats().row_misses, 0u);
  EXPECT_GT(counted.dev->stats().sdram_accesses, 0u);
  EXPECT_EQ(plain.dev->stats().pixels_covered, counted.dev->stats().pixels_covered);
  const auto a = plain.dev->memory(), b = counted.dev->memory();
  EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end()));
}

// A triangle's texture footprint: vertices at texel (0, 0), (16, 0), (0, 16) of a 16 x 16 RGB565
// texture (S = 0.5, Q = 0.5: one texture width) cover 128 texels.
TEST(SimSdramRows, TexelFootprintIsTheTextureSpaceAreaCappedBySamples) {
  Triangle t;
  const std::int32_t half = 1 << 23;  // s8.24: 0.5
  t.v[0].s = 0, t.v[0].t = 0;
  t.v[1].s = half, t.v[1].t = 0;
  t.v[2].s = 0, t.v[2].t = half;
  for (auto& v : t.v) v.q = 0x80000000u;  // u0.32: 0.5
  DrawState st;
  st.tex.wl = st.tex.hl = 4;
  st.tex.format = protocol::PixelFormat::RGB565;
  st.tex.bilinear = false;
  EXPECT_EQ(texel_footprint_bytes(t, st, 1000), (128u + 1u) * 2u);  // the area, plus one texel
  EXPECT_EQ(texel_footprint_bytes(t, st, 100), 100u * 2u);          // no more than the samples
  st.tex.bilinear = true;  // a border: 128 + 2·sqrt(128) + 1 texels
  EXPECT_EQ(texel_footprint_bytes(t, st, 1000), static_cast<std::uint64_t>(std::llround((128 + 2 * std::sqrt(128.0) + 1) * 2)));
  EXPECT_EQ(texel_footprint_bytes(t, st, 10), 10u * 4u * 2u);
  t.v[1].q = 0;  // no reciprocal: every sample's bytes
  EXPECT_EQ(texel_footprint_bytes(t, st, 1000), 1000u * 4u * 2u);
}

TEST(SimSdramRows, RowAndRefreshTermsInTheEstimate) {
  DeviceStats w;
  w.sdram_accesses = 1000;
  w.row_opens = 10;
  w.row_misses = 100;
  BoardTiming b;
  b.memory_bound = false;
  b.cycles_per_command = 0;
  const double base = estimate_timing(w, b, 4).pipeline_cycles;
  b.cycles_per_sdram_access = 2;
  b.cycles_per_row_open = 2;
  b.cycles_per_row_miss = 5;
  EXPECT_DOUBLE_EQ(estimate_timing(w, b, 4).pipeline_cycles, base + 1000 * 2 + 10 * 2 + 100 * 5);
  // a refresh of 8 clocks every 400: the work is 98 % of the board's time
  b.refresh_interval_cycles = 400;
  b.cycles_per_refresh = 8;
  EXPECT_DOUBLE_EQ(refresh_stretch(b), 1.0 / (1.0 - 8.0 / 400.0));
  EXPECT_DOUBLE_EQ(estimate_timing(w, b, 4).pipeline_cycles, (base + 2520) / 0.98);
  // the keys of the settings
  ASSERT_TRUE(apply_timing_setting(b, "cycles_per_row_miss=6.5"));
  ASSERT_TRUE(apply_timing_setting(b, "refresh_interval_cycles=0"));
  EXPECT_EQ(b.cycles_per_row_miss, 6.5);
  EXPECT_EQ(refresh_stretch(b), 1.0);
  // the ecp5 preset refreshes every 7.8 us at 50 MHz, 2 + 4 + 2 clocks (tRP, tRFC, tRCD)
  auto e = timing_preset("ecp5");
  ASSERT_TRUE(e);
  EXPECT_EQ(e->refresh_interval_cycles, 390);
  EXPECT_EQ(e->cycles_per_refresh, 8);
  EXPECT_GT(e->cycles_per_row_miss, 0);
  EXPECT_EQ(e->clock_mhz, 50);
  EXPECT_FALSE(e->memory_bound);
  auto u = timing_preset("up5k");
  ASSERT_TRUE(u);
  EXPECT_EQ(u->cycles_per_row_miss, 0);
  EXPECT_EQ(refresh_stretch(*u), 1.0);
}

// The texel cache (core_texture.v): direct mapped by texel parity, eight texel rows of any width.
TEST(SimSdramRows, TexelCacheHoldsEightTexelRows) {
  TexelCache c;
  c.begin(1);
  for (unsigned j = 0; j < 8; ++j)
    for (unsigned i = 0; i < 300; ++i) EXPECT_FALSE(c.lookup(i, j)) << i << "," << j;
  for (unsigned j = 0; j < 8; ++j)
    for (unsigned i = 0; i < 300; ++i) EXPECT_TRUE(c.lookup(i, j)) << "held: " << i << "," << j;
  EXPECT_EQ(c.misses(), 8u * 300u);
  EXPECT_FALSE(c.lookup(5, 8));  // the ninth row takes row 0's entry of that texel
  EXPECT_FALSE(c.lookup(5, 0));
  EXPECT_TRUE(c.lookup(6, 0));   // the others stay
  EXPECT_FALSE(c.lookup(5, 8));
  c.begin(1);  // the same draw continues: kept
  EXPECT_TRUE(c.lookup(7, 3));
  c.begin(2);  // another texture or buffers: forgotten
  EXPECT_FALSE(c.lookup(7, 3));
  c.invalidate();
  c.begin(2);  // anything between (a clear, an untextured triangle): forgotten as well
  EXPECT_FALSE(c.lookup(7, 3));
  c.reset_counts();
  EXPECT_EQ(c.misses(), 0u);
  EXPECT_EQ(c.hits(), 0u);
}

constexpr unsigned kTextured = 2;
constexpr std::uint32_t kTexBase = 0x80000;

// A textured triangle over a 64 x 48 RGBA8888 canvas, its texture (log2 size `lg`, RGBA8888,
// nearest, REPEAT) spanning `widths` texture widths across the triangle.
void textured_tri(Canvas& cv, unsigned lg, int widths) {
  w(*cv.dev, Reg::TEX_BASE, kTexBase);
  w(*cv.dev, Reg::TEX_FMT, (lg << 4) | lg);
  w(*cv.dev, Reg::TRI_MODE, kTextured);
  const std::int32_t one = widths << 24;  // s8.24 over q = 1.0 (u0.32 just below 1)
  const int x[3] = {2 * 16, 60 * 16, 9 * 16}, y[3] = {3 * 16, 5 * 16, 40 * 16};
  const std::int32_t s[3] = {0, one, 0}, t[3] = {0, 0, one};
  w(*cv.dev, Reg::PRIM, 0);
  for (int k = 0; k < 3; ++k) {
    w(*cv.dev, Reg::COLOR, color(0xFFFFFFFF, 0xFFFFFFFFu));
    w(*cv.dev, Reg::TEXCOORD, (std::uint64_t{static_cast<std::uint32_t>(s[k])} << 32) | static_cast<std::uint32_t>(t[k]));
    w(*cv.dev, Reg::VERTEX, vtx(x[k], y[k]));
  }
}

// The device replays a textured triangle's texel lookups: a magnified 8 x 8 texture is read once
// per texel and kept for the next triangle of the same draw, forgotten after a clear; every miss
// is a read in the row stream beside the colour writes; a minified texture misses about once a
// pixel; the textured draw's row misses are counted apart.
TEST(SimSdramRows, TexelCacheMissesAreReadsInTheRowStream) {
  DeviceOptions counting;
  counting.sdram_rows = true;
  Canvas cv(64, 48, 0, counting);
  cv.dev->reset_stats();
  textured_tri(cv, 3, 1);
  const DeviceStats first = cv.dev->stats();
  ASSERT_GT(first.pixels_covered, 500u);
  EXPECT_GT(first.texel_fetches, 16u);
  EXPECT_LE(first.texel_fetches, 64u) << "magnified: each texel once";
  // RGBA8888 colour without depth or blend: a write per pixel, plus the texel reads
  EXPECT_EQ(first.sdram_accesses, first.pixels_covered + first.texel_fetches);
  EXPECT_EQ(first.textured_row_misses, first.row_misses);
  textured_tri(cv, 3, 1);
  EXPECT_EQ(cv.dev->stats().texel_fetches, first.texel_fetches) << "the same draw keeps its texels";
  w(*cv.dev, Reg::CLEAR, 0);
  textured_tri(cv, 3, 1);
  EXPECT_EQ(cv.dev->stats().texel_fetches, 2 * first.texel_fetches) << "a clear forgets them";
  // minified: 8 texture widths of a 64 x 64 texture across the triangle, a new texel most pixels
  cv.dev->reset_stats();
  textured_tri(cv, 6, 8);
  const DeviceStats minified = cv.dev->stats();
  EXPECT_GT(minified.texel_fetches, minified.pixels_covered / 2);
  EXPECT_GT(minified.row_misses, first.row_misses);
  EXPECT_EQ(minified.textured_row_misses, minified.row_misses);
  // an untextured draw's misses are not the textured ones
  cv.dev->reset_stats();
  w(*cv.dev, Reg::TRI_MODE, kZTest | kLess | kZWrite);
  cv.tri(2 * 16, 3 * 16, 60 * 16, 5 * 16, 9 * 16, 40 * 16);
  EXPECT_EQ(cv.dev->stats().texel_fetches, 0u);
  EXPECT_EQ(cv.dev->stats().textured_row_misses, 0u);
}

// The terms of the texel reads, the row misses of textured and untextured draws and the depth
// writes (the passed pixels of the depth classes), each on its own count.
TEST(SimSdramRows, TexelReadMissSplitAndDepthWriteTermsInTheEstimate) {
  DeviceStats w;
  w.by_mode[2].pixels = 100;  // z
  w.by_mode[0].pixels = 50;   // flat: passes what it covers
  w.pixels_depth_passed = 120;
  w.row_misses = 40;
  w.textured_row_misses = 15;
  w.texel_fetches = 30;
  EXPECT_EQ(depth_writes(w), 70u);
  BoardTiming b;
  b.memory_bound = false;
  const double base = estimate_timing(w, b, 4).pipeline_cycles;
  b.cycles_per_row_miss = 2;  // the 25 untextured misses
  EXPECT_DOUBLE_EQ(estimate_timing(w, b, 4).pipeline_cycles, base + 25 * 2);
  b.cycles_per_textured_row_miss = 1;
  EXPECT_DOUBLE_EQ(estimate_timing(w, b, 4).pipeline_cycles, base + 25 * 2 + 15 * 1);
  b.cycles_per_texel_fetch = 3;
  EXPECT_DOUBLE_EQ(estimate_timing(w, b, 4).pipeline_cycles, base + 65 + 30 * 3);
  b.cycles_per_depth_write = 5;
  EXPECT_DOUBLE_EQ(estimate_timing(w, b, 4).pipeline_cycles, base + 155 + 70 * 5);
  ASSERT_TRUE(apply_timing_setting(b, "cycles_per_textured_row_miss=1.5"));
  ASSERT_TRUE(apply_timing_setting(b, "cycles_per_texel_fetch=0.5"));
  ASSERT_TRUE(apply_timing_setting(b, "cycles_per_depth_write=4"));
  EXPECT_EQ(b.cycles_per_textured_row_miss, 1.5);
  EXPECT_EQ(b.cycles_per_texel_fetch, 0.5);
  EXPECT_EQ(b.cycles_per_depth_write, 4);
  EXPECT_EQ(stats_difference(w, DeviceStats{}).textured_row_misses, 15u);
  EXPECT_EQ(stats_difference(w, DeviceStats{}).texel_fetches, 30u);
  // the ecp5 preset charges depth writes; up5k (no depth buffer, no SDRAM) none of these
  auto e = timing_preset("ecp5"), u = timing_preset("up5k");
  ASSERT_TRUE(e && u);
  EXPECT_GT(e->cycles_per_depth_write, 0);
  EXPECT_EQ(u->cycles_per_depth_write + u->cycles_per_textured_row_miss + u->cycles_per_texel_fetch, 0);
}

// A depth-class triangle's last pixels (the depth stage's 4 reads in flight) are counted once per
// triangle, at most its covered pixels; other classes count none. Their credit subtracts, and
// never makes a negative time.
TEST(SimSdramRows, DepthTailPixelsPerDepthTriangle) {
  DeviceOptions counting;
  counting.sdram_rows = true;
  Canvas cv(64, 48, 0, counting);
  w(*cv.dev, Reg::TRI_MODE, kZTest | kLess | kZWrite);
  cv.dev->reset_stats();
  cv.tri(2 * 16, 3 * 16, 60 * 16, 5 * 16, 9 * 16, 40 * 16);
  cv.tri(2 * 16, 3 * 16, 60 * 16, 5 * 16, 9 * 16, 40 * 16);
  EXPECT_EQ(cv.dev->stats().depth_tail_pixels, 2u * 4u);
  cv.dev->reset_stats();
  cv.tri(10 * 16, 10 * 16, 12 * 16, 10 * 16, 10 * 16, 12 * 16);  // a 2 x 2 corner: fewer than 4 pixels
  const DeviceStats tiny = cv.dev->stats();
  ASSERT_GT(tiny.pixels_covered, 0u);
  ASSERT_LT(tiny.pixels_covered, 4u);
  EXPECT_EQ(tiny.depth_tail_pixels, tiny.pixels_covered);
  cv.dev->reset_stats();
  w(*cv.dev, Reg::TRI_MODE, 0);  // flat, no depth
  cv.tri(2 * 16, 3 * 16, 60 * 16, 5 * 16, 9 * 16, 40 * 16);
  EXPECT_EQ(cv.dev->stats().depth_tail_pixels, 0u);

  DeviceStats work;
  work.depth_tail_pixels = 40;
  work.queued_executed = 100;
  BoardTiming b;
  b.memory_bound = false;
  const double base = estimate_timing(work, b, 4).pipeline_cycles;  // 100 commands at 1 cycle
  ASSERT_TRUE(apply_timing_setting(b, "drained_cycles_per_tail_pixel=2"));
  EXPECT_DOUBLE_EQ(estimate_timing(work, b, 4).pipeline_cycles, base - 40 * 2);
  b.drained_cycles_per_tail_pixel = 100;
  EXPECT_EQ(estimate_timing(work, b, 4).pipeline_cycles, 0.0);
  EXPECT_EQ(stats_difference(work, DeviceStats{}).depth_tail_pixels, 40u);
  auto e = timing_preset("ecp5"), u = timing_preset("up5k");
  ASSERT_TRUE(e && u);
  EXPECT_GT(e->drained_cycles_per_tail_pixel, 0);
  EXPECT_EQ(u->drained_cycles_per_tail_pixel, 0);
}

}  // namespace
}  // namespace gpubridge::sim::test
