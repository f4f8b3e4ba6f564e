// The exact path's texel coordinates in vector lanes (texel_coords8, texture8.hpp) against the
// scalar reciprocal unit and texel_coords (texture.hpp) they replace: every table size and
// Newton-Raphson step count of the accuracy knobs, every texture size, q = 0, q = 1, powers of two
// and their neighbours (every leading-zero count), the largest q and random ones, negative and
// extreme s and t. Checked in the baseline build of the lanes and, where the CPU has it, in an
// AVX2 build (the one the span routine's AVX2 clone inlines).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "texture8.hpp"

namespace gpubridge::sim::test {
namespace {

void lanes_default(const ReciprocalUnit& r, const std::uint32_t* s, const std::uint32_t* t, const std::uint32_t* q,
                   unsigned wl, unsigned hl, TexelCoords* out) {
  texel_coords8(r, s, t, q, wl, hl, out);
}

__attribute__((target("avx2"))) void lanes_avx2(const ReciprocalUnit& r, const std::uint32_t* s,
                                                const std::uint32_t* t, const std::uint32_t* q, unsigned wl,
                                                unsigned hl, TexelCoords* out) {
  texel_coords8(r, s, t, q, wl, hl, out);
}

// The q values worth checking: 0, every power of two and its neighbours, the largest.
std::vector<std::uint32_t> edge_qs() {
  std::vector<std::uint32_t> qs = {0, 1, 2, 3, 0xFFFFFFFFu, 0xFFFFFFFEu, 0x80000001u};
  for (unsigned b = 1; b < 32; ++b) {
    const std::uint32_t p = std::uint32_t{1} << b;
    qs.insert(qs.end(), {p - 1, p, p + 1});
  }
  return qs;
}

TEST(SimTexelLanes, SameCoordinatesAsTheScalarUnit) {
  std::mt19937 rng(17);
  const std::vector<std::uint32_t> edges = edge_qs();
  const bool avx2 = __builtin_cpu_supports("avx2");
  const std::uint32_t extreme[] = {0, 1, 0x7FFFFFFFu, 0x80000000u, 0xFFFFFFFFu, 0x12345678u};
  unsigned checked = 0, nonzero = 0, negative = 0;
  for (unsigned bits = 1; bits <= 16; ++bits) {
    for (unsigned steps = 0; steps <= 4; ++steps) {
      const ReciprocalUnit unit(bits, steps);
      for (unsigned round = 0; round < 40; ++round) {
        const unsigned wl = rng() % 11, hl = rng() % 11;  // 1 .. 1024 texels a side
        std::uint32_t s[8], t[8], q[8];
        for (unsigned k = 0; k < 8; ++k) {
          q[k] = round % 2 == 0 ? edges[rng() % edges.size()] : static_cast<std::uint32_t>(rng()) >> (rng() % 32);
          s[k] = round % 5 == 0 ? extreme[rng() % 6] : static_cast<std::uint32_t>(rng());
          t[k] = round % 7 == 0 ? extreme[rng() % 6] : static_cast<std::uint32_t>(rng());
        }
        TexelCoords base[8], wide[8];
        lanes_default(unit, s, t, q, wl, hl, base);
        if (avx2) lanes_avx2(unit, s, t, q, wl, hl, wide);
        for (unsigned k = 0; k < 8; ++k) {
          TexelCoords want;  // the scalar routine's rule: q = 0 samples at (0, 0)
          if (q[k] != 0)
            want = texel_coords(static_cast<std::int32_t>(s[k]), static_cast<std::int32_t>(t[k]), unit(q[k]), wl, hl);
          ASSERT_EQ(base[k].tu, want.tu) << "bits " << bits << " steps " << steps << " q " << q[k] << " s " << s[k];
          ASSERT_EQ(base[k].tv, want.tv) << "bits " << bits << " steps " << steps << " q " << q[k] << " t " << t[k];
          if (avx2) {
            ASSERT_EQ(wide[k].tu, want.tu) << "avx2, bits " << bits << " steps " << steps << " q " << q[k];
            ASSERT_EQ(wide[k].tv, want.tv) << "avx2, bits " << bits << " steps " << steps << " q " << q[k];
          }
          ++checked;
          nonzero += want.tu != 0;
          negative += want.tu < 0;
        }
      }
    }
  }
  EXPECT_EQ(checked, 16u * 5u * 40u * 8u);
  EXPECT_GT(nonzero, checked / 2);  // the inputs reach real coordinates, both signs
  EXPECT_GT(negative, checked / 8);
}

}  // namespace
}  // namespace gpubridge::sim::test
