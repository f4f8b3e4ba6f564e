// The band workers' rows (backends/sim/src/band_split.hpp): a batch's rows cut into one run of
// whole 16-row bands per worker where the estimated work splits evenly. The bytes do not depend on
// the cuts (band_setup_test.cpp and the scenes' CRCs check that at 1-3 threads); these check the
// cuts themselves: whole bands, in order, covering every row, where the work is, and afresh for
// every batch; moved by the work the workers measured on the batch before (kept per batch since a
// flush), and tall triangles' work spread over their rows.
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
    s.split(n, 0, cuts);
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
  s.split(2, 0, cuts);
  expect_well_formed(cuts, 2);
  EXPECT_GE(cuts[1], 400);
  EXPECT_LT(cuts[1], 480);
  // The estimate starts afresh: the same rows the other way round cut near the top.
  s.add(0, 80, 512 * 80 * 600);
  for (int y = 160; y < 480; y += 4) s.add(y, y + 4, 512 * 4 * 2);
  s.split(2, 0, cuts);
  EXPECT_GT(cuts[1], 0);
  EXPECT_LE(cuts[1], 80);
}

TEST(SimBandSplit, NothingAddedGivesEveryRowToOneWorker) {
  BandSplit s;
  std::vector<int> cuts;
  s.split(3, 0, cuts);
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
    s.split(n, 0, cuts);
    expect_well_formed(cuts, n);
  }
}


// One row of 20 px on each of rows 0..479 (even work: the cut at row 240 for two workers).
void add_even_rows(BandSplit& s) {
  for (int y = 0; y < 480; ++y) s.add(y, y + 1, 512 * 20);
}

TEST(SimBandSplit, MeasuredWorkMovesTheCut) {
  for (const bool lower_heavy : {true, false}) {
    BandSplit s;
    std::vector<int> cuts;
    add_even_rows(s);
    s.split(2, 0, cuts);
    ASSERT_EQ(cuts[1], 240);
    // The worker below the cut took three times the other's work: it gets fewer rows next time.
    s.measured(lower_heavy ? std::vector<std::int64_t>{1000, 3000} : std::vector<std::int64_t>{3000, 1000});
    add_even_rows(s);
    s.split(2, 0, cuts);
    expect_well_formed(cuts, 2);
    if (lower_heavy) {
      EXPECT_GT(cuts[1], 240);
      EXPECT_LE(cuts[1], 320);
    } else {
      EXPECT_LT(cuts[1], 240);
      EXPECT_GE(cuts[1], 160);
    }
  }
}

TEST(SimBandSplit, WorkMeasuredAsEstimatedKeepsTheWeights) {
  BandSplit s;
  std::vector<int> cuts;
  for (int batch = 0; batch < 4; ++batch) {
    add_even_rows(s);
    s.split(2, 0, cuts);
    EXPECT_EQ(cuts[1], 240) << batch;
    s.measured({7000, 7000});  // the same measured work for the same estimated work
  }
  for (int band = 0; band < BandSplit::kBands; ++band) EXPECT_EQ(s.weight(0, band), BandSplit::kWeightOne) << band;
}

TEST(SimBandSplit, NothingMeasuredLeavesTheWeights) {
  BandSplit s;
  std::vector<int> cuts;
  add_even_rows(s);
  s.split(2, 0, cuts);
  s.measured({0, 0});
  s.measured({5, 1, 1});  // not this batch's workers
  add_even_rows(s);
  s.split(2, 0, cuts);
  EXPECT_EQ(cuts[1], 240);
  for (int band = 0; band < BandSplit::kBands; ++band) EXPECT_EQ(s.weight(0, band), BandSplit::kWeightOne) << band;
}

// Triangles of all 480 rows: spread over their bands, the weights can move the cut (all in the
// middle row's band, the cut would stay at row 240 whatever was measured).
TEST(SimBandSplit, TallTrianglesFollowTheMeasuredWork) {
  BandSplit s;
  std::vector<int> cuts;
  auto add_tall = [&] {
    for (int i = 0; i < 100; ++i) s.add(0, 480, 512 * 50000);
  };
  add_tall();
  s.split(2, 0, cuts);
  EXPECT_EQ(cuts[1], 240);
  s.measured({3000, 1000});
  add_tall();
  s.split(2, 0, cuts);
  EXPECT_LT(cuts[1], 240);
  EXPECT_GE(cuts[1], 160);
}

// Tall slivers (under 4 px a row) stay in their middle row's band: the fan's spread ran slower.
TEST(SimBandSplit, TallSliversStayInTheirMiddleBand) {
  BandSplit s;
  std::vector<int> cuts;
  auto add_slivers = [&] {
    for (int i = 0; i < 100; ++i) s.add(0, 480, 512 * 400);
  };
  add_slivers();
  s.split(2, 0, cuts);
  EXPECT_EQ(cuts[1], 240);
  s.measured({3000, 1000});
  add_slivers();
  s.split(2, 0, cuts);
  EXPECT_EQ(cuts[1], 240);  // all in band 15: no weight moves it
}

TEST(SimBandSplit, WeightsAreKeptPerBatchSinceAFlush) {
  BandSplit s;
  std::vector<int> cuts;
  add_even_rows(s);
  s.split(2, 0, cuts);
  s.measured({3000, 1000});  // the first batch after a flush: heavy at the top
  const std::int64_t top = s.weight(0, 0), bottom = s.weight(0, 20);
  EXPECT_GT(top, BandSplit::kWeightOne);  // the top's work weighs more than estimated
  EXPECT_LT(bottom, BandSplit::kWeightOne);
  EXPECT_EQ(s.weight(1, 0), BandSplit::kWeightOne);  // the second batch's set: not measured yet
  // The second batch starts from the first's weights, then is measured heavy at the bottom.
  add_even_rows(s);
  s.split(2, 1, cuts);
  EXPECT_LT(cuts[1], 240);
  s.measured({500, 3500});
  EXPECT_LT(s.weight(1, 0), top);
  EXPECT_EQ(s.weight(0, 0), top);  // the first batch's set is its own
  EXPECT_EQ(s.weight(0, 20), bottom);
  // Batches past the last set share it.
  EXPECT_EQ(s.weight(BandSplit::kBatchSets + 3, 0), s.weight(BandSplit::kBatchSets - 1, 0));
  add_even_rows(s);
  s.split(2, 0, cuts);  // after the next flush: the first set again
  EXPECT_LT(cuts[1], 240);
}

TEST(SimBandSplit, MeasuredWorkCountsWalkedRowsAndShadedPixels) {
  // 2 triangles, 100 rows of which 40 rejected by the coarse depth, 500 pixels shaded.
  EXPECT_EQ(BandSplit::measured_work(2, 100, 40, 500),
            2 * BandSplit::kTriangleWork + 60 * BandSplit::kRowWork + 40 * BandSplit::kSkippedRowWork + 500);
  EXPECT_EQ(BandSplit::measured_work(0, 5, 9, 0), 9 * BandSplit::kSkippedRowWork);  // more rejected than counted
  // The preview's triangles weigh their own unit (its pixels cost less).
  EXPECT_EQ(BandSplit::measured_work(3, 10, 0, 7, BandSplit::kPreviewTriangleWork),
            3 * BandSplit::kPreviewTriangleWork + 10 * BandSplit::kRowWork + 7);
  EXPECT_GT(BandSplit::kPreviewTriangleWork, BandSplit::kTriangleWork);
}

}  // namespace
}  // namespace gpubridge::sim::test
