#pragma once
// Which rows of a batch each band worker draws (renderer.hpp): N runs of whole 16-row bands, one
// after another down the screen, cut where an estimate of the batch's drawing work is split evenly.
// A triangle is then drawn by one worker in one run, as one thread draws it, unless a cut crosses
// it; with bands dealt round-robin (band i → worker i % N) a 45-row triangle crossed three bands,
// and both workers built a Kernel for it and stepped over each other's rows (docs/simulator.md,
// "the exact path at two threads"). Any cuts give the same bytes: the workers' rows are disjoint
// and each pixel is still written in submission order.
//
// The estimate is a triangle's work added to the band of its middle row (one add on the device
// thread: spreading it over its rows cost a division and three stores a triangle, +3 % of the
// device thread's instructions on 10-px triangles, where that thread is the critical path): its
// rows times a row's cost, its area, and a Kernel's set-up, in pixels' worth of work. A cut through
// a triangle then counts all of its work on one side, as often the one as the other. Tall, wide
// triangles (more than four bands, 4 px a row) are spread over their bands: few, each worth the division.
//
// What the estimate cannot see is corrected by what the workers did (measured()): after a batch
// each worker reports its work counted the same way but from what it drew (its rows of each
// triangle, the covered pixels it shaded: not those the coarse depth rejected, which are most of a
// random-Z scene's and not spread evenly down the screen), and each band's weight becomes the ratio
// of measured to estimated work in the run that held it (against the batch's mean), averaged with
// its weight so far. Counts, not times: the cuts are the same in every run (and no cut changes a
// byte), whatever the machine's load. The weights are kept per batch since the last flush (the
// first batch after a frame's clear rejects nothing, the last ones nearly everything: one set of
// weights carried from one to the next was always a batch behind), the batches past the sixth
// sharing one set.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::sim {

class BandSplit {
 public:
  static constexpr int kBandRows = 16;  // cuts fall between the coarse depth blocks' bands
  static constexpr int kMaxRows = 2048;  // a clip rectangle's rows (below 2^11)
  // What a row and a triangle's set-up cost against a drawn pixel (callgrind, 1,000-px triangles:
  // about 22 instructions a pixel in the span routine, 300 a row in the row loop, 1,500 a Kernel),
  // and a row the coarse depth rejected (50,000-px random Z, callgrind over three frames: about 60
  // instructions a row in EdgeWalk::count and 53 in the band and row asks, against 12.7 a shaded
  // pixel there, most of whose pixels fail the depth test).
  static constexpr std::int64_t kRowWork = 14, kTriangleWork = 70, kSkippedRowWork = 9;
  // A triangle's measured work at `--accuracy preview` (measured_work's triangle_work): its pixels
  // cost less there (lanes of 8 and 16), so a triangle's set-up and calls weigh more against them.
  // The preview fan (14,400 slivers) at 70 kept its cut a band off: the worker with more triangles
  // executed 62.6 M instructions against 58.8 M; from 100 to 140 they are 60.7 and 60.5 M. At 180
  // and more the preview tri50k-random's slower worker took 2 % more (callgrind, docs/simulator.md
  // branch sim-pv).
  static constexpr std::int64_t kPreviewTriangleWork = 140;
  // Band weights: 1 << kWeightBits is "as estimated"; a run's weight stays within [1/8, 8] of the mean.
  static constexpr int kWeightBits = 10;
  static constexpr std::int64_t kWeightOne = std::int64_t{1} << kWeightBits;
  // Batches since a flush with weights of their own (Renderer: the first holds 128 triangles and
  // each next one twice as many up to 4,096, the sixth).
  static constexpr unsigned kBatchSets = 6;

  static constexpr int kBands = kMaxRows / kBandRows;
  // add() indexes work_ by a triangle's middle row: every framebuffer the options accept must fit.
  static_assert(kMaxRows >= static_cast<int>(protocol::kMaxFramebufferDim),
                "BandSplit's table must cover the tallest framebuffer");

  BandSplit() {
    for (auto& set : weight_) set.fill(kWeightOne);
  }

  // A triangle of rows y0..y1-1 (0 <= y0 < y1 <= kMaxRows) and twice its area `den` in 1/16 px
  // units (so den is its area in 1/512 px, the estimate's unit).
  void add(int y0, int y1, std::int64_t den) {
    const std::int64_t work = den + ((kTriangleWork + kRowWork * (y1 - y0)) << 9);
    if (y1 - y0 <= kSpreadRows || den < static_cast<std::int64_t>(y1 - y0) * (kSpreadWidth << 9)) {
      work_[static_cast<std::size_t>((y0 + y1) >> 1) / kBandRows] += work;
      return;
    }
    // A tall, wide triangle: its work spread evenly over its bands (a difference array, summed by
    // split()). In its middle band, the cuts of a batch of 50,000-px triangles all fell near the
    // screen's middle row however the work lay, and no weight could move them by less than the
    // middle bands' whole estimate. Tall slivers stay in their middle band: the fan's (200 rows,
    // under 2 px wide) spread ran 7 % slower at two threads with the same instructions (wall and
    // CPU time, eight rounds; not explained), and faster than main's without the spread.
    const int b0 = y0 / kBandRows, b1 = (y1 - 1) / kBandRows;
    const std::int64_t per_band = work / (b1 - b0 + 1);
    spread_[static_cast<std::size_t>(b0)] += per_band;
    spread_[static_cast<std::size_t>(b1) + 1] -= per_band;
  }

  // cuts[0..n]: worker w draws rows cuts[w]..cuts[w+1]-1 (cuts[0] = 0, cuts[n] = kMaxRows), whole
  // bands each, the weighted estimate as even as whole bands allow. `batch`: batches handed over
  // since the last flush before this one (0 for the first). Clears the estimate and keeps each
  // run's share of it for measured().
  void split(unsigned n, unsigned batch, std::vector<int>& cuts) {
    set_ = std::min(batch, kBatchSets - 1);
    // A set never measured starts from the one measured last (this flush's previous batch).
    if (!measured_set_[set_] && set_ > 0) weight_[set_] = weight_[set_ - 1];
    const auto& weight = weight_[set_];
    std::int64_t spread = 0;  // the tall triangles' work in band b (the difference array's running sum)
    for (std::size_t b = 0; b < kBands; ++b) work_[b] += spread += spread_[b];
    spread_.fill(0);
    std::array<std::int64_t, kBands> weighted;
    std::int64_t total = 0;
    for (std::size_t b = 0; b < kBands; ++b) total += weighted[b] = work_[b] * weight[b] >> kWeightBits;
    cuts.assign(n + 1, 0);
    cuts[n] = kMaxRows;
    // Cut k after the band where the running sum comes nearest k·total/n (nothing added: every
    // row to worker 0).
    std::int64_t sum = 0;
    std::size_t b = 0;
    for (unsigned k = 1; k < n; ++k) {
      const double target = static_cast<double>(total) * k / n;
      while (b < kBands && static_cast<double>(sum) + 0.5 * static_cast<double>(weighted[b]) < target) sum += weighted[b++];
      cuts[k] = total == 0 ? kMaxRows : static_cast<int>(b) * kBandRows;
    }
    estimated_.assign(n, 0);
    for (unsigned w = 0; w < n; ++w)
      for (int band = cuts[w] / kBandRows; band < cuts[w + 1] / kBandRows; ++band)
        estimated_[w] += work_[static_cast<std::size_t>(band)];
    cuts_ = cuts;
    work_.fill(0);
  }

  // A worker's measured work on its rows of a batch, in pixels' worth (the estimate's unit over
  // 512): its triangles, their rows it walked, the rows the coarse depth rejected and the covered
  // pixels it shaded (the counts the instructions follow: on 50,000-px random Z the two workers'
  // measured work over three frames came within 1 % of their instructions' ratio).
  static std::int64_t measured_work(std::uint64_t triangles, std::uint64_t rows, std::uint64_t skipped_rows,
                                    std::uint64_t shaded, std::int64_t triangle_work = kTriangleWork) {
    const std::uint64_t walked = rows > skipped_rows ? rows - skipped_rows : 0;
    return static_cast<std::int64_t>(static_cast<std::uint64_t>(triangle_work) * triangles + kRowWork * walked +
                                     kSkippedRowWork * skipped_rows + shaded);
  }

  // The batch cut by the last split() took measured[w] (measured_work) on worker w's rows: each
  // band of run w weighs the run's measured over estimated work, relative to the whole batch's,
  // averaged with its weight so far (one batch of a few hundred triangles is a noisy sample). Runs
  // with nothing estimated, and a batch with nothing measured, leave their bands' weights.
  void measured(const std::vector<std::int64_t>& measured) {
    if (measured.size() != estimated_.size()) return;
    std::int64_t m_total = 0, e_total = 0;
    for (std::size_t w = 0; w < measured.size(); ++w) m_total += measured[w], e_total += estimated_[w];
    if (m_total <= 0 || e_total <= 0) return;
    auto& weight = weight_[set_];
    for (std::size_t w = 0; w < measured.size(); ++w) {
      if (estimated_[w] <= 0) continue;
      // (m / e) / (m_total / e_total) in 1/kWeightOne (doubles: the products overflow 64 bits).
      const double ratio = static_cast<double>(measured[w]) / static_cast<double>(m_total) *
                           (static_cast<double>(e_total) / static_cast<double>(estimated_[w]));
      const std::int64_t rel = std::clamp(static_cast<std::int64_t>(ratio * kWeightOne), kWeightOne / 8, kWeightOne * 8);
      for (int band = cuts_[w] / kBandRows; band < cuts_[w + 1] / kBandRows; ++band) {
        std::int64_t& wt = weight[static_cast<std::size_t>(band)];
        wt = (wt + rel + 1) >> 1;
      }
    }
    measured_set_[set_] = true;
    estimated_.clear();  // measured once
  }

  // Band `band`'s weight in the set of batch `batch` since a flush (kWeightOne: as estimated).
  std::int64_t weight(unsigned batch, int band) const {
    return weight_[std::min(batch, kBatchSets - 1)][static_cast<std::size_t>(band)];
  }

 private:
  // Triangles of more rows than this spread their work over their bands (add()): one division
  // each, too much for the device thread on small triangles, where it is the critical path.
  static constexpr int kSpreadRows = 4 * kBandRows;
  // ... and at least this many pixels a row on average (16 left the cubes' tall faces in one band:
  // their slower worker 33.6 M instructions, main's, against 31.8 M spread).
  static constexpr std::int64_t kSpreadWidth = 4;
  using Bands = std::array<std::int64_t, kBands>;
  Bands work_{};  // per band: the work of the triangles whose middle row is in it
  std::array<std::int64_t, kBands + 1> spread_{};  // the tall triangles' work per band, as differences
  std::array<Bands, kBatchSets> weight_;  // per set, per band: measured over estimated work, in 1/kWeightOne
  std::array<bool, kBatchSets> measured_set_{};  // the set's weights were measured at least once
  unsigned set_ = 0;  // the last split()'s set
  std::vector<std::int64_t> estimated_;  // per run of the last split(): its estimated work
  std::vector<int> cuts_;  // the last split()'s cuts
};

}  // namespace gpubridge::sim
