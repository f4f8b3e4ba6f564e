// The plain preview kernel's texture stage in its instances (backends/sim/src/preview_plain.cpp):
// the AVX2 and AVX-512 instances load the two columns of a bilinear texel row as one 64-bit word
// per lane (sim-preview14), the baseline instance word by word. Every instance must store the
// same bytes, all four channels (the comparison with the float routine in preview_test.cpp sees
// only RGB), and count the same pixels: random textures 8 to 128 texels a side in every wrap
// mode (REPEAT's seam, the edges of CLAMP and MIRROR, MIRROR's reflected copies), nearest and
// bilinear, decal and modulate, perspective Q that sometimes falls to 0 or below, and random
// depths, blend and boxes.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "preview_box_edges.hpp"
#include "preview_plain.hpp"
#include "setup.hpp"

namespace gpubridge::sim::test {
namespace {

constexpr unsigned kW = 96, kH = 40;  // the buffers' size in pixels

struct Case {
  PreviewPlain p;
  int y0 = 0;  // the box origin's row
  FixedPlanes planes;
  FloatPlanes tex_planes;
  std::vector<std::uint8_t> color, depth, texels;
};

Case random_case(std::mt19937& rng) {
  Case c;
  random_buffer(rng, c.color, kW, kH);
  random_buffer(rng, c.depth, kW, kH);
  int x[3], y[3];
  random_points(rng, x, y, kW, kH);
  const PreviewBox b = place_triangle(x, y, c.p, c.planes, kW);
  c.y0 = b.by0;
  PreviewPlain& p = c.p;
  random_planes(rng, c.planes);
  p.ky0 = 0;
  p.rows = std::min(b.by1, static_cast<int>(kH)) - b.by0;
  random_depth_test(rng, p, 3);
  p.zmask = 0xFFFFFFu;
  p.blend = rng() % 3 == 0 ? protocol::BlendMode::Alpha : protocol::BlendMode::Off;
  // The texture and its S, T, Q planes (per pixel of the box, as the renderer's double planes):
  // coordinates over a few texture widths either side of 0, so every wrap mode meets its edges.
  PreviewTexels& t = p.tex;
  t.wl = 3 + rng() % 5;
  t.hl = 3 + rng() % 5;
  c.texels.resize(std::size_t{4} << (t.wl + t.hl));
  for (auto& byte : c.texels) byte = static_cast<std::uint8_t>(rng());
  const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * (rng() / 4294967296.0); };
  const bool perspective = rng() % 2 != 0;
  const double q = perspective ? uniform(0.05, 2.0) : 1.0;
  c.tex_planes.base[kS] = uniform(-3, 3) * q;
  c.tex_planes.base[kT] = uniform(-3, 3) * q;
  c.tex_planes.base[kQ] = q;
  for (unsigned a = kS; a <= kQ; ++a) {
    const double range = a == kQ ? (perspective ? 0.03 : 0.0) : uniform(0.001, 0.2);
    c.tex_planes.dx[a] = uniform(-range, range);
    c.tex_planes.dy[a] = uniform(-range, range);
  }
  t.texels = c.texels.data();
  t.planes = &c.tex_planes;
  t.wrap_s = static_cast<protocol::Wrap>(rng() % 3);
  t.wrap_t = static_cast<protocol::Wrap>(rng() % 3);
  t.bilinear = rng() % 4 != 0;
  t.decal = rng() % 2 != 0;
  t.scale_u = std::ldexp(1.0f, 20 + static_cast<int>(t.wl));
  t.scale_v = std::ldexp(1.0f, 20 + static_cast<int>(t.hl));
  return c;
}

PreviewCounts draw(ShadeRoutine shade, const Case& c, std::vector<std::uint8_t>& color, std::vector<std::uint8_t>& depth) {
  return draw_case(shade, c, kW, color, depth);
}

TEST(SimPreviewTexels, InstancesSampleTheSameBytes) {
  const ShadeRoutine reference = shade_instance(0);
  ASSERT_NE(reference, nullptr);
  if (!shade_instance(1) && !shade_instance(2)) GTEST_SKIP() << "no AVX2 on this CPU";
  std::mt19937 rng(1424);
  std::uint64_t passed = 0;
  unsigned wraps_seen = 0, bilinear_cases = 0;
  for (int n = 0; n < 3000; ++n) {
    const Case c = random_case(rng);
    if (c.p.rows <= 0 || c.p.width <= 0) continue;
    std::vector<std::uint8_t> color0, depth0;
    const PreviewCounts want = draw(reference, c, color0, depth0);
    for (unsigned isa = 1; isa < 3; ++isa) {
      const ShadeRoutine shade = shade_instance(isa);
      if (!shade) continue;
      std::vector<std::uint8_t> color, depth;
      const PreviewCounts got = draw(shade, c, color, depth);
      ASSERT_TRUE(same_draw(got, want, color, color0, depth, depth0)) << "case " << n << " isa " << isa;
    }
    passed += want.passed;
    wraps_seen |= 1u << static_cast<unsigned>(c.p.tex.wrap_s);
    bilinear_cases += c.p.tex.bilinear;
  }
  EXPECT_GT(passed, 100000u);
  EXPECT_EQ(wraps_seen, 7u);
  EXPECT_GT(bilinear_cases, 1000u);
}

// Bilinear triangles whose Q step along x is ±0 in float (sim-constq) take instances that work out
// 1/Q once per row (AVX2, AVX-512); the instances that divide in every chunk must store the same
// bytes and counts for them (nearest draws, which always divide, come along as a control):
// steps of +0, −0 and of a double too small for a float, Q changing from row to row and on some
// boxes reaching 0 and below (those rows sample texel (0, 0)), in every instance on this CPU.
TEST(SimPreviewTexels, FlatQRowsSampleAsTheDividingInstances) {
  std::mt19937 rng(2424);
  std::uint64_t passed = 0;
  unsigned bilinear_cases = 0, nearest_cases = 0, through_zero = 0, instances = 0;
  for (unsigned isa = 0; isa < 3; ++isa) instances += shade_instance(isa) != nullptr;
  ASSERT_GT(instances, 0u);
  for (int n = 0; n < 3000; ++n) {
    Case c = random_case(rng);
    if (c.p.rows <= 0 || c.p.width <= 0) continue;
    const double flat_steps[4] = {0.0, -0.0, 1e-50, -1e-50};  // all ±0 as floats
    c.p.planes = &c.planes;  // this copy's planes
    c.p.tex.planes = &c.tex_planes;
    const double q = rng() % 4 == 0 ? 0.02 * (rng() % 3) - 0.02 : c.tex_planes.base[kQ];  // some from -0.02 to 0.02
    c.tex_planes.base[kQ] = q;
    c.tex_planes.dx[kQ] = flat_steps[rng() % 4];
    c.tex_planes.dy[kQ] = (rng() % 2 ? 0.01 : -0.01) * (rng() % 4);
    ASSERT_EQ(static_cast<float>(c.tex_planes.dx[kQ]), 0.0f);
    const double q_last = q + c.tex_planes.dy[kQ] * (c.p.rows - 1);
    through_zero += (q <= 0) != (q_last <= 0) || q <= 0;
    for (unsigned isa = 0; isa < 3; ++isa) {
      const ShadeRoutine flat = shade_instance(isa), dividing = dividing_shade_instance(isa);
      if (!flat) continue;
      ASSERT_NE(dividing, nullptr);
      std::vector<std::uint8_t> color0, depth0, color, depth;
      const PreviewCounts want = draw(dividing, c, color0, depth0);
      const PreviewCounts got = draw(flat, c, color, depth);
      ASSERT_TRUE(same_draw(got, want, color, color0, depth, depth0)) << "case " << n << " isa " << isa;
      if (isa == 0) passed += want.passed;
    }
    bilinear_cases += c.p.tex.bilinear;
    nearest_cases += !c.p.tex.bilinear;
  }
  EXPECT_GT(passed, 100000u);
  EXPECT_GT(bilinear_cases, 1000u);
  EXPECT_GT(nearest_cases, 300u);
  EXPECT_GT(through_zero, 300u);
}

}  // namespace
}  // namespace gpubridge::sim::test
