// Rasterisation and primitive assembly (docs/protocol.md sections 7-9, 12), against values derived
// independently from the document (reference.hpp) and hand-counted examples.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "reference.hpp"
#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

using namespace protocol;

TEST(SimRaster, D3DExampleCovers15And10Pixels) {
  Canvas a(8, 8);
  a.tri(0, 0, 5 * 16, 0, 5 * 16, 5 * 16);
  EXPECT_EQ(a.count_nonzero(), 15u);
  Canvas b(8, 8);
  b.tri(0, 5 * 16, 0, 0, 5 * 16, 5 * 16);
  EXPECT_EQ(b.count_nonzero(), 10u);
  // Together: every pixel of the 5x5 square exactly once (ADD blend of 1 per triangle).
  Canvas c(8, 8);
  w(*c.dev, Reg::TRI_MODE, 2u << 7);
  c.tri(0, 0, 80, 0, 80, 80, 0x01010101, 0x01010101, 0x01010101);
  c.tri(0, 80, 0, 0, 80, 80, 0x01010101, 0x01010101, 0x01010101);
  for (unsigned y = 0; y < 8; ++y)
    for (unsigned x = 0; x < 8; ++x) EXPECT_EQ(c.rgba(x, y), x < 5 && y < 5 ? 0x01010101u : 0u) << x << "," << y;
}

// Every pixel of the canvas against the independent transcription of the document (reference.hpp):
// empty where it samples nothing, its Gouraud colour and (when `depth`) depth where it does. Counts
// the covered pixels of each row into `per_row` (one entry per row).
void expect_reference_pixels(const Canvas& c, const ref::P (&p)[3], const std::uint32_t (&cols)[3],
                             const std::uint32_t (&zs)[3], int width, int height, int iter,
                             std::vector<unsigned>& per_row, bool depth = true) {
  per_row.assign(static_cast<std::size_t>(height), 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const ref::Bary s = ref::sample(p[0], p[1], p[2], x, y);
      if (!s.covered) {
        ASSERT_EQ(c.rgba(x, y), 0u) << "iter " << iter << " pixel " << x << "," << y << " should be empty";
        continue;
      }
      ++per_row[static_cast<std::size_t>(y)];
      std::uint32_t expect = 0;
      for (int ch = 0; ch < 4; ++ch) {
        const int sh = 24 - 8 * ch;
        const auto v = ref::interpolate(s, {(cols[0] >> sh) & 255, (cols[1] >> sh) & 255, (cols[2] >> sh) & 255});
        expect |= static_cast<std::uint32_t>(v) << sh;
      }
      ASSERT_EQ(c.rgba(x, y), expect) << "iter " << iter << " pixel " << x << "," << y;
      if (depth) {
        ASSERT_EQ(c.depth(x, y), static_cast<std::uint32_t>(ref::interpolate(s, {zs[0], zs[1], zs[2]})))
            << "iter " << iter << " pixel " << x << "," << y;
      }
    }
}

// Coverage and Gouraud/Z values of random triangles (narrow ones use the per-pixel test, wide
// ones the span solver) against the reference transcription.
TEST(SimRaster, CoverageAndAttributesMatchReference) {
  std::mt19937 rng(1234);
  std::uniform_int_distribution<int> coord(-200, 64 * 16 + 200);
  std::uniform_int_distribution<std::uint32_t> col(0, 0xFFFFFFFFu), zd(0, 0xFFFFFF);
  for (int iter = 0; iter < 60; ++iter) {
    Canvas c(64, 48);
    w(*c.dev, Reg::TRI_MODE, 1 | (1u << 6));  // Gouraud, Z write (no test)
    const int small = iter % 2;               // half of them small
    ref::P p[3];
    std::uint32_t cols[3], zs[3];
    for (int i = 0; i < 3; ++i) {
      p[i] = {coord(rng), coord(rng) * 3 / 4};
      if (small && i > 0) p[i] = {p[0].x + coord(rng) % 97, p[0].y + coord(rng) % 83};
      cols[i] = col(rng);
      zs[i] = zd(rng);
    }
    c.tri(static_cast<int>(p[0].x), static_cast<int>(p[0].y), static_cast<int>(p[1].x), static_cast<int>(p[1].y),
          static_cast<int>(p[2].x), static_cast<int>(p[2].y), cols[0], cols[1], cols[2], zs[0], zs[1], zs[2]);
    std::vector<unsigned> per_row;
    ASSERT_NO_FATAL_FAILURE(expect_reference_pixels(c, p, cols, zs, 64, 48, iter, per_row));
  }
}

// Long thin triangles (the `fan` scene's slivers: rows of 0-3 pixels whose first pixel moves by
// changing distances, rows with no sample between covered ones) and triangles clipped by the
// canvas, with the vector routines and with the reference routines. Wide rows find their span ends
// by stepping each edge's quotient and keep the planes at each span's first pixel, carried from row
// to row (rasterizer.cpp, Kernel::run_wide); every pixel's colour and depth must still equal the
// independent transcription of the document (reference.hpp).
TEST(SimRaster, SliversAndClippedTrianglesMatchReference) {
  std::mt19937 rng(4321);
  std::uniform_int_distribution<int> coord(-300, 128 * 16 + 300), off(-40, 40);
  std::uniform_int_distribution<std::uint32_t> col(0, 0xFFFFFFFFu), zd(0, 0xFFFFFF);
  unsigned covered = 0, sliver_rows = 0;
  for (int iter = 0; iter < 80; ++iter) {
    DeviceOptions o;
    o.vector_routines = iter % 2 == 0;
    Canvas c(128, 96, 0, o);
    w(*c.dev, Reg::TRI_MODE, 1 | (1u << 6));  // Gouraud, Z write (no test)
    ref::P p[3];
    p[0] = {coord(rng), coord(rng) * 3 / 4};
    p[1] = {coord(rng), coord(rng) * 3 / 4};
    const bool sliver = iter % 4 < 2;  // the third vertex near the middle of the first two
    if (sliver) p[2] = {(p[0].x + p[1].x) / 2 + off(rng), (p[0].y + p[1].y) / 2 + off(rng)};
    else p[2] = {coord(rng), coord(rng) * 3 / 4};
    std::uint32_t cols[3], zs[3];
    for (int i = 0; i < 3; ++i) {
      cols[i] = col(rng);
      zs[i] = zd(rng);
    }
    c.tri(static_cast<int>(p[0].x), static_cast<int>(p[0].y), static_cast<int>(p[1].x), static_cast<int>(p[1].y),
          static_cast<int>(p[2].x), static_cast<int>(p[2].y), cols[0], cols[1], cols[2], zs[0], zs[1], zs[2]);
    std::vector<unsigned> per_row;
    ASSERT_NO_FATAL_FAILURE(expect_reference_pixels(c, p, cols, zs, 128, 96, iter, per_row));
    for (unsigned in_row : per_row) {
      covered += in_row;
      if (sliver && in_row > 0 && in_row < 8) ++sliver_rows;
    }
  }
  EXPECT_GT(covered, 10000u);     // the triangles drew something
  EXPECT_GT(sliver_rows, 200u);   // and the slivers gave short rows (the pixel-by-pixel spans)
}

// The `fan` scene's triangles: slivers from a pixel centre out to a radius, thinner than a pixel
// for most of their length, so their box rows are empty (no sample between the edges), one pixel
// or a few; boxes of every width from 1 up (9-15 and wider take the edge walk). Drawn with and
// without depth and with the vector routines on (the colour planes step in lanes: the cursor, its
// row steps over empty rows and the pixels of short spans, color_cursor.hpp) and off; every
// pixel's colour (and depth) against the reference transcription.
TEST(SimRaster, FanSliversWithEmptyRowsMatchReference) {
  std::mt19937 rng(2468);
  std::uniform_real_distribution<double> angle(0, 2 * 3.14159265358979), width(0.004, 0.06), radius(40, 75);
  std::uniform_int_distribution<std::uint32_t> col(0, 0xFFFFFFFFu), zd(0, 0xFFFFFF);
  unsigned empty_rows = 0, short_rows = 0, wide_boxes = 0, mid_boxes = 0;
  for (int iter = 0; iter < 96; ++iter) {
    DeviceOptions o;
    o.vector_routines = iter % 4 != 3;
    const bool depth = iter % 2 == 0;
    Canvas c(160, 120, 0, o);
    w(*c.dev, Reg::TRI_MODE, depth ? 1 | (1u << 6) : 1);  // Gouraud (and Z write)
    const double a0 = angle(rng), a1 = a0 + width(rng), r = radius(rng);
    const int cx = 80 * 16 + 8, cy = 60 * 16 + 8;  // a pixel centre, as the scene's
    ref::P p[3];
    p[0] = {cx, cy};
    p[1] = {cx + std::lround(16 * r * std::cos(a0)), cy + std::lround(16 * r * std::sin(a0))};
    p[2] = {cx + std::lround(16 * r * std::cos(a1)), cy + std::lround(16 * r * std::sin(a1))};
    std::uint32_t cols[3], zs[3];
    for (int i = 0; i < 3; ++i) {
      cols[i] = col(rng);
      zs[i] = zd(rng);
    }
    if (iter % 3 == 0)  // the scene's constant alpha
      for (auto& k : cols) k = (k & 0xFFFFFF00u) | 0xFF;
    c.tri(static_cast<int>(p[0].x), static_cast<int>(p[0].y), static_cast<int>(p[1].x), static_cast<int>(p[1].y),
          static_cast<int>(p[2].x), static_cast<int>(p[2].y), cols[0], cols[1], cols[2], zs[0], zs[1], zs[2]);
    std::vector<unsigned> per_row;
    ASSERT_NO_FATAL_FAILURE(expect_reference_pixels(c, p, cols, zs, 160, 120, iter, per_row, depth));
    int first = -1, last = -1;
    for (int y = 0; y < 120; ++y)
      if (per_row[static_cast<std::size_t>(y)] != 0) {
        if (first < 0) first = y;
        last = y;
      }
    for (int y = first; first >= 0 && y <= last; ++y) {
      const unsigned n = per_row[static_cast<std::size_t>(y)];
      empty_rows += n == 0;
      short_rows += n > 0 && n < 8;
    }
    const long box = (std::max({p[0].x, p[1].x, p[2].x}) - std::min({p[0].x, p[1].x, p[2].x})) / 16;
    wide_boxes += box >= 16;
    mid_boxes += box > 8 && box < 16;
  }
  EXPECT_GT(empty_rows, 300u);   // rows between covered ones with no sample (the walk over empty rows)
  EXPECT_GT(short_rows, 1500u);  // rows of 1-7 pixels (short spans, pixel by pixel)
  EXPECT_GT(wide_boxes, 40u);
  EXPECT_GT(mid_boxes, 3u);
}

TEST(SimRaster, FanAroundSamplePointCoversEachPixelOnce) {
  Canvas c(32, 32);
  w(*c.dev, Reg::TRI_MODE, 2u << 7);  // ADD
  w(*c.dev, Reg::PRIM, 2);            // FAN
  w(*c.dev, Reg::COLOR, color(0x01010101));
  const int cx = 16 * 16 + 8, cy = 16 * 16 + 8;  // exactly on a pixel centre
  w(*c.dev, Reg::VERTEX, vtx(cx, cy));
  const int n = 37;
  for (int i = 0; i <= n; ++i) {
    const double a = 2 * 3.14159265358979 * (i % n) / n;
    w(*c.dev, Reg::VERTEX, vtx(cx + static_cast<int>(180 * std::cos(a)), cy + static_cast<int>(180 * std::sin(a))));
  }
  EXPECT_EQ(c.rgba(16, 16), 0x01010101u);  // the shared vertex's pixel: exactly one triangle
  for (unsigned y = 0; y < 32; ++y)
    for (unsigned x = 0; x < 32; ++x) EXPECT_LE(c.rgba(x, y), 0x01010101u) << x << "," << y;
}

TEST(SimRaster, StripAndFanAssemblyAndFlatColourVertex) {
  Canvas c(16, 16);
  w(*c.dev, Reg::TRI_MODE, 0);  // flat
  w(*c.dev, Reg::PRIM, 1);      // STRIP
  const std::uint32_t cols[4] = {0x11111111, 0x22222222, 0x33333333, 0x44444444};
  const int v[4][2] = {{0, 0}, {0, 128}, {128, 0}, {128, 128}};
  for (int i = 0; i < 4; ++i) {
    w(*c.dev, Reg::COLOR, color(cols[i]));
    w(*c.dev, Reg::VERTEX, vtx(v[i][0], v[i][1]));
  }
  EXPECT_EQ(c.rgba(1, 1), 0x11111111u);  // (v0, v1, v2): first vertex v0
  EXPECT_EQ(c.rgba(6, 6), 0x22222222u);  // (v1, v2, v3): first vertex v1
  EXPECT_EQ(c.dev->stats().triangles_kicked, 2u);

  Canvas f(16, 16);
  w(*f.dev, Reg::PRIM, 2);  // FAN: (v0, v1, v2), (v0, v2, v3)
  const int fv[4][2] = {{0, 0}, {128, 0}, {128, 128}, {0, 128}};
  for (int i = 0; i < 4; ++i) {
    w(*f.dev, Reg::COLOR, color(cols[i]));
    w(*f.dev, Reg::VERTEX, vtx(fv[i][0], fv[i][1]));
  }
  EXPECT_EQ(f.rgba(6, 1), 0x11111111u);
  EXPECT_EQ(f.rgba(1, 6), 0x11111111u);
  EXPECT_EQ(f.dev->stats().triangles_kicked, 2u);
  // A PRIM write restarts counting: two vertices then PRIM then one vertex kick nothing.
  w(*f.dev, Reg::PRIM, 0);
  w(*f.dev, Reg::VERTEX, vtx(0, 0));
  w(*f.dev, Reg::VERTEX, vtx(100, 0));
  w(*f.dev, Reg::PRIM, 0);
  w(*f.dev, Reg::VERTEX, vtx(0, 100));
  EXPECT_EQ(f.dev->stats().triangles_kicked, 2u);
}

TEST(SimRaster, ClearsHonourScissorAndFormat) {
  Canvas c(8, 8);
  w(*c.dev, Reg::SCISSOR, scissor(2, 3, 5, 6));
  w(*c.dev, Reg::CLEAR_COLOR, 0xA1B2C3D4);
  w(*c.dev, Reg::CLEAR, 0);
  w(*c.dev, Reg::CLEAR_DEPTH, 0x123456);
  w(*c.dev, Reg::CLEAR_Z, 0);
  for (unsigned y = 0; y < 8; ++y)
    for (unsigned x = 0; x < 8; ++x) {
      const bool in = x >= 2 && x < 5 && y >= 3 && y < 6;
      EXPECT_EQ(c.rgba(x, y), in ? 0xA1B2C3D4u : 0u);
      EXPECT_EQ(c.depth(x, y), in ? 0x123456u : 0xFFFFFFu);  // the canvas cleared Z to the reset CLEAR_DEPTH
    }
  Canvas s(4, 4, 1);  // RGB565: truncation, no dither
  w(*s.dev, Reg::CLEAR_COLOR, 0xFFFFFFFF);
  w(*s.dev, Reg::TRI_MODE, 1u << 9);  // DITHER must not affect clears
  w(*s.dev, Reg::CLEAR_COLOR, 0x7F3F1FFF);
  w(*s.dev, Reg::CLEAR, 0);
  const unsigned expect = ((0x7Fu >> 3) << 11) | ((0x3Fu >> 2) << 5) | (0x1Fu >> 3);
  EXPECT_EQ((unsigned{s.px(3, 3)[0]} << 8) | s.px(3, 3)[1], expect);
}

TEST(SimRaster, SwapComputesFrameCrcOfTheBufferBytes) {
  Canvas c(16, 8);
  c.tri(0, 0, 200, 10, 30, 120, 0xFF0000FF, 0x00FF00FF, 0x0000FFFF);
  std::shared_ptr<const backends::ScanoutFrame> got;
  c.dev->set_scanout_callback([&](std::shared_ptr<const backends::ScanoutFrame> f) { got = std::move(f); });
  w(*c.dev, Reg::FB_DISPLAY, 0);
  const auto bytes = c.color_bytes();
  const std::uint32_t expect = static_cast<std::uint32_t>(crc32(0, bytes.data(), static_cast<uInt>(bytes.size())));
  EXPECT_EQ(rd(*c.dev, Reg::FRAME_CRC), (1ull << 32) | expect);
  EXPECT_EQ((rd(*c.dev, Reg::STATUS) >> 32) & 0xFFFF, 1u);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->number, 1u);
  EXPECT_EQ(got->crc, expect);
  EXPECT_EQ(got->pixels, bytes);
  EXPECT_EQ(got->width, 16u);
  // Same address again is a swap too.
  w(*c.dev, Reg::FB_DISPLAY, 0);
  EXPECT_EQ(rd(*c.dev, Reg::FRAME_CRC), (2ull << 32) | expect);
}

TEST(SimRaster, ScanoutBeyondVramCountsZeros) {
  DeviceOptions o;
  o.vram_bytes = 64 << 10;
  Canvas c(16, 16, 0, o);
  w(*c.dev, Reg::ERR_CLEAR, 0xFFFF);  // the canvas' depth clear lay beyond this small VRAM
  ASSERT_EQ(errors_of(*c.dev), 0);
  w(*c.dev, Reg::FB_DISPLAY, (64 << 10) - 16 * 4);  // first row inside, the rest beyond
  std::vector<std::uint8_t> bytes(16 * 16 * 4, 0);
  const auto m = c.dev->memory();
  std::copy(m.end() - 64, m.end(), bytes.begin());
  const std::uint32_t expect = static_cast<std::uint32_t>(crc32(0, bytes.data(), static_cast<uInt>(bytes.size())));
  EXPECT_EQ(rd(*c.dev, Reg::FRAME_CRC) & 0xFFFFFFFF, expect);
  EXPECT_EQ(errors_of(*c.dev) & ERR_MEM_RANGE, ERR_MEM_RANGE);
}

}  // namespace
}  // namespace gpubridge::sim::test
