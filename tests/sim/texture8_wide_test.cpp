// The span routine's AVX-512 bilinear filter (texture8_wide.hpp's bilinear_filter_wide, 16-bit
// lanes, the weights regrouped) against section 10.4's sum written here channel by channel:
// every (u, v) fraction pair, each lane its own texels (so a lane or channel out of order fails),
// and the extreme texels 0 and 255 in every channel.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>

#include "texture8_wide.hpp"

namespace gpubridge::sim::test {
namespace {

bool cpu_has_avx512() {
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
         __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
}

// Section 10.4 for one lane: (Σ texel · weight + 2^15) >> 16 per channel, the four weights
// (256 − u)(256 − v), u(256 − v), (256 − u)v, uv.
std::uint32_t reference_bilinear(std::uint32_t t00, std::uint32_t t10, std::uint32_t t01, std::uint32_t t11,
                                 std::uint32_t u, std::uint32_t v) {
  std::uint32_t out = 0;
  for (unsigned c = 0; c < 32; c += 8) {
    const std::uint32_t sum = ((t00 >> c) & 255) * (256 - u) * (256 - v) + ((t10 >> c) & 255) * u * (256 - v) +
                              ((t01 >> c) & 255) * (256 - u) * v + ((t11 >> c) & 255) * u * v + 32768;
    out |= (sum >> 16) << c;
  }
  return out;
}

struct Lanes {
  std::uint32_t t[4][8];  // t00, t10, t01, t11
  std::uint32_t u[8], v[8];
};

TEXTURE8_WIDE_TARGET void filter(const Lanes& in, std::uint32_t* out) {
  simd::u32x8 t[4], u, v, r;
  for (unsigned k = 0; k < 4; ++k) std::memcpy(&t[k], in.t[k], 32);
  std::memcpy(&u, in.u, 32);
  std::memcpy(&v, in.v, 32);
  bilinear_filter_wide(&t[0], &t[1], &t[2], &t[3], &u, &v, &r);
  std::memcpy(out, &r, 32);
}

// Fails on the first lane that differs; returns how many lanes were compared.
unsigned check(const Lanes& in) {
  std::uint32_t out[8];
  filter(in, out);
  for (unsigned k = 0; k < 8; ++k) {
    const std::uint32_t want = reference_bilinear(in.t[0][k], in.t[1][k], in.t[2][k], in.t[3][k], in.u[k], in.v[k]);
    EXPECT_EQ(out[k], want) << "lane " << k << " u " << in.u[k] << " v " << in.v[k];
    if (out[k] != want) return 0;
  }
  return 8;
}

TEST(SimTextureWide, BilinearFilterIsTheSectionSumForEveryWeight) {
  if (!cpu_has_avx512()) GTEST_SKIP() << "this CPU lacks AVX-512 F/VL/BW/DQ";
  std::mt19937 rng(17);
  unsigned compared = 0;
  // Every (u, v): lane k takes u and v + k (mod 256), so each pair is met in every lane position,
  // with random texels in each lane.
  for (unsigned u = 0; u < 256; ++u) {
    for (unsigned v = 0; v < 256; ++v) {
      Lanes in;
      for (unsigned k = 0; k < 8; ++k) {
        for (auto& row : in.t) row[k] = rng();
        in.u[k] = (u + 37 * k) & 255;
        in.v[k] = (v + k) & 255;
      }
      compared += check(in);
      if (::testing::Test::HasFailure()) return;
    }
  }
  // The extremes: each corner 255 and the others 0 (and all 255), each channel alone, at every u, v.
  for (unsigned u = 0; u < 256; ++u) {
    for (unsigned v = 0; v < 256; v += 8) {
      Lanes in;
      for (unsigned k = 0; k < 8; ++k) {
        const std::uint32_t hot = 0xFFu << (8 * (k & 3));
        for (unsigned c = 0; c < 4; ++c) in.t[c][k] = (k < 4 ? c == k : true) ? hot : 0;
        in.u[k] = u;
        in.v[k] = v + k;
      }
      compared += check(in);
      if (::testing::Test::HasFailure()) return;
    }
  }
  EXPECT_EQ(compared, 8u * 65536u + 8u * 256u * 32u);
}

}  // namespace
}  // namespace gpubridge::sim::test
