// The band workers' rows (backends/sim/src/band_split.hpp): a batch's rows cut into one run of
// whole 16-row bands per worker where the estimated work splits evenly. The bytes do not depend on
// the cuts (band_setup_test.cpp and the scenes' CRCs check that at 1-3 threads); these check the
// cuts themselves: whole bands, in order, covering every row, where the work is, and afresh for
// every batch.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "band_split.hpp"

namespace gpubridge::sim::test {
namespace {

constexpr int kBand = BandSplit::kBandRows;

// Cuts are band edges, in order, from row 0 to kMaxRows.
void expect_well_formed(const std::vector<int>& cuts, unsigned n) {
  ASSERT_EQ(cuts.size(), n + 1);
  EXPECT_EQ(cuts.front(), 0);
  EXPECT_EQ(cuts.back(), BandSplit::kMaxRows);
  for (unsigned k = 0; k < n; ++k) {
    EXPECT_EQ(cuts[k] % kBand, 0) << k;
    EXPECT_LE(cuts[k], cuts[k + 1]) << k;
  }
}

TEST(SimBandSplit, EvenWorkIsCutEvenly) {
  BandSplit s;
  std::vector<int> cuts;
  for (unsigned n = 1; n <= 7; ++n) {
    for (int y = 0; y < 480; ++y) s.add(y, y + 1, 512 * 20);  // one row of 20 px on every row
    s.split(n, cuts);
    expect_well_formed(cuts, n);
    for (unsigned k = 1; k < n; ++k) {  // each cut within half a band of k/n of the rows
      const double ideal = 480.0 * k / n;
      EXPECT_LE(std::abs(cuts[k] - ideal), kBand / 2 + 0.01) << n << " workers, cut " << k;
    }
  }
}

TEST(SimBandSplit, CutsFollowTheWork) {
  BandSplit s;
  std::vector<int> cuts;
  // A few wide rows at the bottom outweigh many narrow ones at the top.
  for (int y = 0; y < 320; y += 4) s.add(y, y + 4, 512 * 4 * 2);
  s.add(400, 480, 512 * 80 * 600);
  s.split(2, cuts);
  expect_well_formed(cuts, 2);
  EXPECT_GE(cuts[1], 400);
  EXPECT_LT(cuts[1], 480);
  // The estimate starts afresh: the same rows the other way round cut near the top.
  s.add(0, 80, 512 * 80 * 600);
  for (int y = 160; y < 480; y += 4) s.add(y, y + 4, 512 * 4 * 2);
  s.split(2, cuts);
  EXPECT_GT(cuts[1], 0);
  EXPECT_LE(cuts[1], 80);
}

TEST(SimBandSplit, NothingAddedGivesEveryRowToOneWorker) {
  BandSplit s;
  std::vector<int> cuts;
  s.split(3, cuts);
  expect_well_formed(cuts, 3);
  EXPECT_EQ(cuts[1], BandSplit::kMaxRows);
  EXPECT_EQ(cuts[2], BandSplit::kMaxRows);
}

TEST(SimBandSplit, RandomBatchesGiveWellFormedCuts) {
  std::mt19937 rng(1717);
  BandSplit s;
  std::vector<int> cuts;
  for (int batch = 0; batch < 200; ++batch) {
    const int count = 1 + static_cast<int>(rng() % 300);
    for (int i = 0; i < count; ++i) {
      const int y0 = static_cast<int>(rng() % BandSplit::kMaxRows);
      const int y1 = y0 + 1 + static_cast<int>(rng() % static_cast<unsigned>(BandSplit::kMaxRows - y0));
      s.add(y0, y1, static_cast<std::int64_t>(rng() % 100000000));
    }
    const unsigned n = 1 + rng() % 7;
    s.split(n, cuts);
    expect_well_formed(cuts, n);
  }
}

}  // namespace
}  // namespace gpubridge::sim::test
