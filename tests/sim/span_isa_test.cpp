// The span routine's instruction-set instances (span_simd.cpp: AVX-512 with sixteen lanes, AVX-512
// in 256-bit vectors, AVX2) against the scalar reference routines: random render states and
// triangles rendered with DeviceOptions::vector_routines on and off, colour, depth and counters
// identical. The process runs one instance, the widest the CPU has unless GPUBRIDGE_SIM_SPAN_ISA
// caps it; tests/sim/CMakeLists.txt runs this test again under each cap, so that every instance
// this CPU can run is checked (SimVectorRoutines.* checks only the widest).
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <random>
#include <string>

#include "random_draws.hpp"
#include "span_simd.hpp"

namespace gpubridge::sim::test {
namespace {

bool cpu_has_avx512() {
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
         __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
}

// The instance this process should run, or an empty string when the CPU lacks it (skip).
std::string expected_instance(SpanIsa& isa) {
  const char* env = std::getenv("GPUBRIDGE_SIM_SPAN_ISA");
  const std::string cap = env ? env : "";
  if (cap == "baseline") {
    isa = SpanIsa::Baseline;
    return "baseline";
  }
  if (cap == "avx2") {
    isa = SpanIsa::Avx2;
    return __builtin_cpu_supports("avx2") ? "AVX2" : "";
  }
  isa = cap == "avx512-256" ? SpanIsa::Avx512x256 : SpanIsa::Avx512;
  return cpu_has_avx512() ? (isa == SpanIsa::Avx512 ? "AVX-512 (16 lanes)" : "AVX-512 (256-bit)") : "";
}

TEST(SimSpanIsa, SameBytesAndCountersAsScalar) {
  SpanIsa isa{};
  const std::string name = expected_instance(isa);
  if (name.empty()) GTEST_SKIP() << "this CPU lacks the instruction set of the instance under test (AVX-512 F/VL/BW/DQ, or AVX2 under GPUBRIDGE_SIM_SPAN_ISA=avx2)";
  ASSERT_EQ(span_simd_isa(), isa) << "the span routine does not run the " << name << " instance";
  std::mt19937 rng(20261127);
  unsigned wide = 0, narrow = 0;
  for (int i = 0; i < 400; ++i) {
    Case c = random_case(rng);
    // Half the cases untextured RGBA8888, the states the sixteen-lane routine takes (every depth
    // function, blend and write mask); the other half as drawn (eight lanes, masked tails).
    if (i % 2 == 0) {
      c.tri_mode &= ~std::uint64_t{2};
      c.fb_fmt = fb_format(kW, kH, 0);
    }
    const Rendered v = render(c, vector_options(true)), s = render(c, vector_options(false));
    expect_same(c, v, s, i);
    if (::testing::Test::HasFatalFailure()) return;
    const bool untextured_8888 = !(c.tri_mode & 2) && c.fb_fmt == fb_format(kW, kH, 0);
    (untextured_8888 ? wide : narrow) += s.stats.pixels_depth_passed > 0;
  }
  // Both kinds of state drew pixels.
  EXPECT_GT(wide, 150u);
  EXPECT_GT(narrow, 100u);
}

// Perspective triangles on RGBA8888 bilinear textures that repeat on both axes: the AVX-512
// instances take them through texture8_wide.hpp's lanes (reciprocal, texel coordinates, addressing
// and pair loads), the others through the per-lane loops. The hard cases: Q near 0 (a vertex at
// Q = 0 or at a few units, so that the reciprocal's leading zeros reach 31 and the coordinates'
// shift its smallest), Q at full scale, texture coordinates over the whole signed range (many
// wraps, so that footprints straddle the repeat's seam, where the lanes load word by word) and
// every texture size the random cases draw (8-wide textures: a seam in one footprint of eight),
// and reciprocal tables of 1-16 bits with 0-4 Newton-Raphson steps.
TEST(SimSpanIsa, PerspectiveRepeatTexturesSameBytesAsScalar) {
  SpanIsa isa{};
  const std::string name = expected_instance(isa);
  if (name.empty()) GTEST_SKIP() << "this CPU lacks the instruction set of the instance under test";
  ASSERT_EQ(span_simd_isa(), isa) << "the span routine does not run the " << name << " instance";
  std::mt19937 rng(20261128);
  std::uint64_t textured = 0;
  for (int i = 0; i < 120; ++i) {
    Case c = random_case(rng);
    c.tri_mode |= 2;                                   // textured
    c.tex_fmt &= ~((std::uint64_t{3} << 16) | 0xF00);  // RGBA8888, REPEAT on both axes
    c.tex_fmt |= std::uint64_t{1} << 12;               // bilinear
    const auto draw = [&](const DeviceOptions& o) {
      Canvas cv(kW, kH, 0, o);
      Device& d = *cv.dev;
      std::mt19937 r(c.seed);
      start_frame(d, c, r, true);
      std::uniform_int_distribution<int> px(-16 * 16, (kW + 16) * 16), py(-16 * 16, (kH + 16) * 16);
      std::uniform_int_distribution<int> dv(-60 * 16, 60 * 16);
      for (int t = 0; t < 16; ++t) {
        const int x = px(r), y = py(r);
        w(d, Reg::PRIM, 0);
        for (int k = 0; k < 3; ++k) {
          std::uint32_t q = static_cast<std::uint32_t>(r());
          if (t % 8 == 7) {
            q = 0;  // Q = 0 at every pixel: texel (0, 0) everywhere
          } else if (t % 4 == 3) {
            q = k < 2 ? 0 : q & 0xF;  // Q = 0 along an edge, a few units away from it
          } else {
            switch ((t + k) % 4) {
              case 0: q = k == 0 ? 0 : q & 0xFF; break;  // Q = 0 at a vertex, a few units at the others
              case 1: q &= 0xFFFF; break;
              case 2: q |= 0x80000000u; break;  // full scale
              default: break;
            }
          }
          w(d, Reg::COLOR, color(static_cast<std::uint32_t>(r()), q));
          w(d, Reg::TEXCOORD, (std::uint64_t{static_cast<std::uint32_t>(r())} << 32) | static_cast<std::uint32_t>(r()));
          const std::uint32_t z = static_cast<std::uint32_t>(r()) & 0xFFFFFF;
          w(d, Reg::VERTEX, vtx(k == 0 ? x : x + dv(r), k == 0 ? y : y + dv(r), z));
        }
      }
      return end_frame(d);
    };
    // The reciprocal unit's table sizes and steps: the lanes compute the table's words (b <= 16).
    DeviceOptions on = vector_options(true), off = vector_options(false);
    on.accuracy.recip_bits = off.accuracy.recip_bits = i % 3 == 0 ? 10 : 1 + static_cast<unsigned>(rng() % 16);
    on.accuracy.nr_steps = off.accuracy.nr_steps = i % 3 == 0 ? 1 : static_cast<unsigned>(rng() % 5);
    const Rendered v = draw(on), s = draw(off);
    expect_same(c, v, s, i);
    if (::testing::Test::HasFatalFailure()) return;
    textured += s.stats.pixels_textured;
  }
  EXPECT_GT(textured, 50000u);  // the cases drew textured pixels
}

}  // namespace
}  // namespace gpubridge::sim::test
