// The hard-case classes of the accuracy suite (tests/accuracy) drawn by the render core and by the
// simulator: coverage (shared edges in every octant and both windings, the D3D example, a fan of
// 720 triangles around a sample centre, jittered meshes, zero-area triangles, slivers thinner than
// 1/16 pixel, guard-band triangles at the ends of the coordinate range, scissors on edges),
// attributes (depth near the top of its range with a tiny gradient, equal-depth passes, long spans,
// vertex order and translation), texturing (Q = 0, every reciprocal-table interval end, wrap seams
// with negative coordinates) and the pixel pipeline (blend corners, every value through the
// dither). The accuracy suite bounds the simulator against exact references; here the core must
// leave exactly the simulator's bytes.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "cosim.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "rtl_config.hpp"

namespace gpubridge::rtl {
namespace {

using protocol::Reg;

struct V {
  int x = 0, y = 0;  // 1/16 pixel
  std::uint32_t z = 0, rgba = 0xFFFFFFFFu, q = 0xFFFFFFFFu;
  std::int32_t s = 0, t = 0;
};
using Tri = std::array<V, 3>;

class Bench {
 public:
  Bench(unsigned w, unsigned h, unsigned fmt = 0) : cs_(options(), 4321), w_(w), h_(h) {
    const unsigned bpp = fmt == 0 ? 4 : fmt == 1 ? 2 : 1;
    cs_.write(Reg::FB_FORMAT, (std::uint64_t{fmt} << 32) | (std::uint64_t{h} << 16) | w);
    cs_.write(Reg::FB_DRAW, 0);
    z_base_ = (std::uint32_t(w * h * bpp) + 255) & ~255u;
    cs_.write(Reg::FB_Z, z_base_);
    tex_base_ = (z_base_ + w * h * 4 + 255) & ~255u;
    cs_.write(Reg::TEX_BASE, tex_base_);
    scissor(0, 0, 1024, 1024);
    cs_.write(Reg::CLEAR_COLOR, 0x00000000);
    cs_.write(Reg::CLEAR, 0);
    cs_.write(Reg::CLEAR_DEPTH, 0xFFFFFF);
    cs_.write(Reg::CLEAR_Z, 0);
  }
  static sim::DeviceOptions options() {
    sim::DeviceOptions o;
    o.vram_bytes = std::min<std::uint64_t>(kCoreVramBytes, 4u << 20);
    o.features = kCoreFeatures;
    o.max_width = o.max_height = 1024;
    return o;
  }
  void scissor(unsigned x0, unsigned y0, unsigned x1, unsigned y1) {
    cs_.write(Reg::SCISSOR, x0 | (std::uint64_t{y0} << 16) | (std::uint64_t{x1} << 32) | (std::uint64_t{y1} << 48));
  }
  void mode(std::uint64_t m) { cs_.write(Reg::TRI_MODE, m); }
  void draw(const std::vector<Tri>& tris) {
    cs_.write(Reg::PRIM, 0);
    for (const auto& t : tris)
      for (const auto& v : t) {
        cs_.write(Reg::COLOR, (std::uint64_t{v.q} << 32) | v.rgba);
        cs_.write(Reg::TEXCOORD, (std::uint64_t{std::uint32_t(v.s)} << 32) | std::uint32_t(v.t));
        cs_.write(Reg::VERTEX, (std::uint64_t{v.z & 0xFFFFFF} << 32) | (std::uint64_t{std::uint16_t(v.y)} << 16) |
                                   std::uint16_t(v.x));
      }
  }
  // Flat triangles, each in its own colour: overlaps and gaps show in the bytes.
  void draw_coloured(std::vector<Tri> tris, unsigned seed) {
    std::mt19937 rng(seed);
    for (auto& t : tris) {
      const std::uint32_t c = rng() | 0xFF;
      for (auto& v : t) v.rgba = c;
    }
    draw(tris);
  }
  void texture(const std::vector<std::uint8_t>& bytes, std::uint32_t tex_fmt) {
    cs_.upload(tex_base_, bytes.data(), bytes.size());
    cs_.write(Reg::TEX_FMT, tex_fmt);
  }
  void expect_same(const std::string& what) {
    const std::string diff = cs_.compare();
    EXPECT_TRUE(diff.empty()) << what << ":\n" << diff;
  }
  unsigned w() const { return w_; }
  unsigned h() const { return h_; }

 private:
  Cosim cs_;
  unsigned w_, h_;
  std::uint32_t z_base_ = 0, tex_base_ = 0;
};

int snap(double v) { return int(std::floor(16 * v + 0.5)); }

TEST(CoreHardCases, Coverage) {
  Bench b(64, 64);
  // shared edges in the 8 octants, both windings
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> len(40, 400);
  std::vector<Tri> tris;
  for (int octant = 0; octant < 8; ++octant)
    for (int winding = 0; winding < 2; ++winding)
      for (int k = 0; k < 6; ++k) {
        const double angle = (octant + 0.1 + 0.8 * (k + 0.5) / 6.0) * std::numbers::pi / 4;
        const int l = len(rng), cx = 32 * 16 + 3 * k, cy = 32 * 16 - 5 * k;
        const int ex = cx + int(std::lround(l * std::cos(angle))), ey = cy + int(std::lround(l * std::sin(angle)));
        const int nx = -(ey - cy) / 2, ny = (ex - cx) / 2;
        Tri a{V{cx, cy}, V{ex, ey}, V{(cx + ex) / 2 + nx, (cy + ey) / 2 + ny}};
        Tri c{V{ex, ey}, V{cx, cy}, V{(cx + ex) / 2 - nx, (cy + ey) / 2 - ny}};
        if (winding) {
          std::swap(a[0], a[1]);
          std::swap(c[0], c[1]);
        }
        tris.push_back(a);
        tris.push_back(c);
      }
  b.draw_coloured(tris, 2);
  b.expect_same("shared edges");
  // the D3D example and a square of two triangles
  b.draw_coloured({{V{0, 0}, V{80, 0}, V{80, 80}}, {V{0, 80}, V{0, 0}, V{80, 80}},
                   {V{168, 168}, V{328, 168}, V{328, 328}}, {V{168, 168}, V{328, 328}, V{168, 328}}}, 3);
  b.expect_same("D3D example");
  // a fan of 720 triangles around a sample centre
  tris.clear();
  const int cx = 32 * 16 + 8, cy = 32 * 16 + 8, r = 28 * 16;
  for (int i = 0; i < 720; ++i) {
    const double a0 = 2 * std::numbers::pi * i / 720, a1 = 2 * std::numbers::pi * (i + 1) / 720;
    tris.push_back({V{cx, cy}, V{cx + int(std::lround(r * std::cos(a0))), cy + int(std::lround(r * std::sin(a0)))},
                    V{cx + int(std::lround(r * std::cos(a1))), cy + int(std::lround(r * std::sin(a1)))}});
  }
  b.draw_coloured(tris, 4);
  b.expect_same("fan");
  // zero-area triangles and slivers thinner than 1/16 pixel
  b.draw_coloured({{V{100, 100}, V{100, 100}, V{500, 300}}, {V{8, 8}, V{8, 8}, V{8, 8}},
                   {V{0, 0}, V{320, 160}, V{640, 320}}, {V{-32768, -32768}, V{0, 0}, V{32767, 32767}},
                   {V{24, 40}, V{1000, 40}, V{500, 40}}}, 5);
  tris.clear();
  for (int i = 0; i < 60; ++i) {
    const double x = 4 + i * 0.9 + 0.013 * i, w = 1.0 / 64;
    tris.push_back({V{snap(x), snap(3.3)}, V{snap(x + w), snap(3.3)}, V{snap(x + w), snap(60.7)}});
    tris.push_back({V{snap(x + w), snap(3.3)}, V{snap(x + 2 * w), snap(60.7)}, V{snap(x + w), snap(60.7)}});
  }
  b.draw_coloured(tris, 6);
  b.expect_same("zero area and slivers");
  // scissors on edges
  for (const auto& s : {std::array<unsigned, 4>{10, 20, 40, 50}, {11, 21, 63, 64}, {0, 0, 10, 20}}) {
    b.scissor(s[0], s[1], s[2], s[3]);
    b.draw_coloured({{V{10 * 16 + 8, -200}, V{10 * 16 + 8, 1200}, V{1400, 500}},
                     {V{-300, 20 * 16 + 8}, V{700, 20 * 16 + 8}, V{300, 1500}}}, 7 + s[0]);
  }
  b.scissor(0, 0, 1024, 1024);
  b.expect_same("scissor");
}

TEST(CoreHardCases, JitteredMeshesAndGuardBand) {
  Bench b(kCoreVramBytes >= (2u << 20) ? 640 : 160, kCoreVramBytes >= (2u << 20) ? 480 : 120);
  for (int k = 0; k < 4; ++k) {
    std::mt19937 rng(10 + k);
    std::uniform_real_distribution<double> jitter(-0.45, 0.45);
    const int cells_x = 15, cells_y = 11;
    const double cell = 8.0, offset = k / 32.0;
    std::vector<V> grid;
    for (int j = 0; j <= cells_y; ++j)
      for (int i = 0; i <= cells_x; ++i) {
        const bool border = i == 0 || j == 0 || i == cells_x || j == cells_y;
        grid.push_back(V{snap(2 + i * cell + offset + (border ? 0 : jitter(rng))),
                         snap(2 + j * cell + offset + (border ? 0 : jitter(rng)))});
      }
    std::vector<Tri> tris;
    std::bernoulli_distribution diag(0.5);
    auto at = [&](int i, int j) { return grid[j * (cells_x + 1) + i]; };
    for (int j = 0; j < cells_y; ++j)
      for (int i = 0; i < cells_x; ++i) {
        if (diag(rng)) {
          tris.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
          tris.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        } else {
          tris.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
          tris.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
        }
      }
    b.draw_coloured(tris, 20 + k);
    b.expect_same("jittered mesh " + std::to_string(k));
  }
  // the whole coordinate range
  b.draw_coloured({{V{-32768, -32768}, V{32767, -32768}, V{32760, 32760}},
                   {V{-32768, -32768}, V{32760, 32760}, V{-32768, 32767}}}, 30);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> far(-32768, 32767);
  for (int k = 0; k < 12; ++k) b.draw_coloured({{V{far(rng), far(rng)}, V{far(rng), far(rng)}, V{far(rng), far(rng)}}}, 31 + k);
  b.expect_same("guard band");
}

TEST(CoreHardCases, Attributes) {
  Bench b(kCoreVramBytes >= (2u << 20) ? 1024 : 320, 24);
  // depth near the top of its range with a tiny gradient, written then tested for equality
  b.mode(0x1 | 0x4 | (3u << 3) | 0x40);  // GOURAUD, Z_TEST LEQUAL, Z_WRITE
  std::vector<Tri> deep{{V{0, 0, 0xFFFFF0, 0xFF0000FF}, V{16 * 300, 16, 0xFFFFFF, 0x00FF00FF}, V{0, 16 * 20, 0xFFFFF8, 0x0000FFFF}}};
  b.draw(deep);
  b.mode(0x1 | 0x4 | (2u << 3));  // EQUAL: every pixel of the same triangle passes again
  for (auto& v : deep[0]) v.rgba ^= 0x7F7F7F00;
  b.draw(deep);
  b.expect_same("depth near the top");
  // a span over the whole width, colours 0 .. 255 and back; then the vertex order rotated and the
  // triangle moved by whole pixels
  b.mode(0x1);
  const int w = int(b.w()) * 16;
  std::vector<Tri> longs{{V{0, 8, 0, 0x000000FF}, V{w - 1, 8, 0, 0xFFFFFFFF}, V{w / 2, 16 * 20, 0, 0x80FF00FF}}};
  b.draw(longs);
  b.draw({{longs[0][1], longs[0][2], longs[0][0]}});
  Tri moved = longs[0];
  for (auto& v : moved) v.y += 16 * 2, v.x -= 16 * 3;
  b.draw({moved});
  b.expect_same("long spans");
  // the widest colour numerators: a triangle over the whole coordinate range with colours near
  // 255 makes the value at the origin about 255 * 2D, above 2^41 (the up5k divider takes 45 bits
  // of a colour numerator), in both windings
  std::vector<Tri> huge{{V{32767, 32767, 0, 0xFFFFFFFF}, V{-32768, 32767, 0, 0xFEFDFCFF},
                         V{32767, -32768, 0, 0xFDFEFFFE}}};  // the screen lies inside it
  b.draw(huge);
  b.draw({{huge[0][0], huge[0][2], huge[0][1]}});
  b.expect_same("widest colour numerators");
}

TEST(CoreHardCases, Texturing) {
  if (!kCoreTexture) GTEST_SKIP() << "the profile has no texture unit";
  Bench b(128, 64);
  // a 1024 x 8 texture of position codes, bilinear and nearest, every wrap mode
  std::vector<std::uint8_t> tex(1024 * 8 * 4);
  for (unsigned j = 0; j < 8; ++j)
    for (unsigned i = 0; i < 1024; ++i) {
      std::uint8_t* p = &tex[(j * 1024 + i) * 4];
      p[0] = std::uint8_t(i), p[1] = std::uint8_t(i >> 8), p[2] = std::uint8_t(j * 37), p[3] = std::uint8_t(i * 7 + j);
    }
  auto quad = [](int x0, int y0, int x1, int y1, std::array<std::uint32_t, 4> q, std::array<double, 4> u,
                 std::array<double, 4> v) {
    const int xs[4] = {x0, x1, x1, x0}, ys[4] = {y0, y0, y1, y1};
    V c[4];
    for (int i = 0; i < 4; ++i)
      c[i] = V{xs[i] * 16, ys[i] * 16, 0, 0xFFFFFFFF, q[i], std::int32_t(std::lround(u[i] * q[i] / 256.0)),
               std::int32_t(std::lround(v[i] * q[i] / 256.0))};
    return std::vector<Tri>{{c[0], c[1], c[2]}, {c[0], c[2], c[3]}};
  };
  for (unsigned bilinear = 0; bilinear < 2; ++bilinear)
    for (unsigned wrap = 0; wrap < 3; ++wrap) {
      b.texture(tex, 10 | (3u << 4) | (wrap << 8) | (wrap << 10) | (bilinear << 12));
      b.mode(0x2 | (1u << 14));  // TEXTURED, DECAL
      // every reciprocal-table interval end (q = 0x80000000 | i << 21 and the interval's last value)
      std::vector<Tri> tris;
      for (std::uint32_t i = 0; i < 1024; i += 3)
        for (int end = 0; end < 2; ++end) {
          const std::uint32_t q = 0x80000000u | (i << 21) | (end ? (1u << 21) - 1 : 0);
          const int cell = int(i / 3) * 2 + end, x = (cell % 64) * 2, y = (cell / 64) * 2;
          for (auto& t : quad(x, y, x + 2, y + 2, {q, q, q, q}, {3.97, 3.99, 3.98, 3.96}, {0.3, 0.31, 0.32, 0.33}))
            tris.push_back(t);
        }
      b.draw(tris);
      // seams at k widths, slightly negative coordinates, perspective
      for (double k : {0.0, 1.0, -1.0, -32.0, 100.0, -127.0}) {
        const double du = 8.0 / 1024;
        b.draw(quad(0, 0, 64, 64, {0xFFFFFFFF, 0xC0000000, 0xFFFFFFFF, 0xC0000000}, {k - du, k + du, k + du, k - du},
                    {0.1, 0.1, 0.9, 0.9}));
      }
      // q = 0 at a vertex, and everywhere
      b.draw(quad(64, 0, 128, 32, {0, 0xFFFFFFFF, 0x10000000, 0}, {0.5, 0.25, 2.0, -1.0}, {0.5, 0.1, 0.9, 0.3}));
      b.draw(quad(64, 32, 128, 64, {0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}));
      b.expect_same("texturing, wrap " + std::to_string(wrap) + " bilinear " + std::to_string(bilinear));
    }
}

TEST(CoreHardCases, PixelPipeline) {
  // every value through the dither and the quantisers, at every screen position mod 4
  for (unsigned fmt : {1u, 2u}) {
    if (!(kCoreFeatures & (fmt == 1 ? sim::FEATURE_RGB565 : sim::FEATURE_RGBA2222))) continue;
    Bench b(64, 64, fmt);
    for (unsigned dither = 0; dither < 2; ++dither) {
      if (dither && !(kCoreFeatures & sim::FEATURE_DITHER)) continue;
      b.mode(dither << 9);
      std::vector<Tri> tris;
      for (unsigned v = 0; v < 256; ++v) {
        const int x = int(v % 16) * 4, y = int(v / 16) * 4;
        const std::uint32_t c = v * 0x01010101u;
        tris.push_back({V{x * 16, y * 16, 0, c}, V{(x + 4) * 16, y * 16, 0, c}, V{(x + 4) * 16, (y + 4) * 16, 0, c}});
        tris.push_back({V{x * 16, y * 16, 0, c}, V{(x + 4) * 16, (y + 4) * 16, 0, c}, V{x * 16, (y + 4) * 16, 0, c}});
      }
      b.draw(tris);
      b.expect_same("dither, format " + std::to_string(fmt));
    }
  }
  if (!(kCoreFeatures & sim::FEATURE_BLEND)) return;
  // blend corners: src, dst and alpha at 0, 1, 254, 255 and a middle value, every equation
  Bench b(64, 64);
  const std::uint8_t vals[5] = {0, 1, 128, 254, 255};
  for (unsigned eq = 1; eq < 4; ++eq) {
    b.mode(0);
    std::vector<Tri> dst, src;
    for (int i = 0; i < 125; ++i) {
      const int x = (i % 16) * 4, y = (i / 16) * 4;
      const std::uint32_t d = vals[i % 5] * 0x01010101u;
      const std::uint32_t s = (vals[(i / 5) % 5] * 0x01010100u) | vals[i / 25];
      dst.push_back({V{x * 16, y * 16, 0, d}, V{(x + 4) * 16, y * 16, 0, d}, V{(x + 4) * 16, (y + 4) * 16, 0, d}});
      src.push_back({V{x * 16, y * 16, 0, s}, V{(x + 4) * 16, y * 16, 0, s}, V{(x + 4) * 16, (y + 4) * 16, 0, s}});
    }
    b.draw(dst);
    b.mode(eq << 7);
    b.draw(src);
    b.expect_same("blend " + std::to_string(eq));
  }
}

}  // namespace
}  // namespace gpubridge::rtl
