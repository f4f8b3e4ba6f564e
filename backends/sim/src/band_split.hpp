#pragma once
// Which rows of a batch each band worker draws (renderer.hpp): N runs of whole 16-row bands, one
// after another down the screen, cut where an estimate of the batch's drawing work is split evenly.
// A triangle is then drawn by one worker in one run, as one thread draws it, unless a cut crosses
// it; with bands dealt round-robin (band i → worker i % N) a 45-row triangle crossed three bands,
// and both workers built a Kernel for it and stepped over each other's rows (docs/simulator.md,
// "the exact path at two threads"). Any cuts give the same bytes: the workers' rows are disjoint
// and each pixel is still written in submission order.
//
// The estimate, per row, is a difference array the device thread adds each set-up triangle to
// (two or three stores): its rows times a row's cost plus its area, spread evenly over its rows,
// plus a Kernel's set-up at its first row, all in pixels' worth of work.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace gpubridge::sim {

class BandSplit {
 public:
  static constexpr int kBandRows = 16;  // cuts fall between the coarse depth blocks' bands
  static constexpr int kMaxRows = 2048;  // a clip rectangle's rows (below 2^11)
  // What a row and a triangle's set-up cost against a drawn pixel (callgrind, 1,000-px triangles:
  // about 22 instructions a pixel in the span routine, 300 a row in the row loop, 1,500 a Kernel).
  static constexpr float kRowWork = 14.f, kTriangleWork = 70.f;

  BandSplit() : diff_(kMaxRows + 2, 0.f) {}

  // A triangle of rows y0..y1-1 (0 <= y0 < y1 <= kMaxRows) and twice its area `den` in 1/16 px units.
  void add(int y0, int y1, double den) {
    const float per_row = kRowWork + static_cast<float>(den * (1.0 / 512)) / static_cast<float>(y1 - y0);
    diff_[static_cast<std::size_t>(y0)] += per_row + kTriangleWork;
    diff_[static_cast<std::size_t>(y0) + 1] -= kTriangleWork;
    diff_[static_cast<std::size_t>(y1)] -= per_row;
    lo_ = std::min(lo_, y0);
    hi_ = std::max(hi_, y1);
  }

  // cuts[0..n]: worker w draws rows cuts[w]..cuts[w+1]-1 (cuts[0] = 0, cuts[n] = kMaxRows), whole
  // bands each, the estimated work as even as whole bands allow. Clears the estimate.
  void split(unsigned n, std::vector<int>& cuts) {
    cuts.assign(n + 1, 0);
    cuts[n] = kMaxRows;
    if (hi_ <= lo_) {  // nothing added: every row to worker 0
      for (unsigned w = 1; w < n; ++w) cuts[w] = kMaxRows;
      return;
    }
    // Work per band, from the first band with a row to the last.
    const int b0 = lo_ / kBandRows, b1 = (hi_ + kBandRows - 1) / kBandRows;
    band_work_.assign(static_cast<std::size_t>(b1 - b0), 0.f);
    float rate = 0.f, total = 0.f;
    for (int y = b0 * kBandRows; y < std::min(b1 * kBandRows, kMaxRows); ++y) {
      rate += diff_[static_cast<std::size_t>(y)];
      band_work_[static_cast<std::size_t>(y / kBandRows - b0)] += rate;
    }
    for (float w : band_work_) total += w;
    // Cut k after the band where the running sum comes nearest k·total/n.
    float sum = 0.f;
    std::size_t b = 0;
    for (unsigned k = 1; k < n; ++k) {
      const float target = total * static_cast<float>(k) / static_cast<float>(n);
      while (b < band_work_.size() && sum + band_work_[b] * 0.5f < target) sum += band_work_[b++];
      cuts[k] = (b0 + static_cast<int>(b)) * kBandRows;
    }
    std::fill(diff_.begin() + lo_, diff_.begin() + std::min(hi_ + 2, kMaxRows + 2), 0.f);
    lo_ = kMaxRows;
    hi_ = 0;
  }

 private:
  std::vector<float> diff_;        // per row: the change of the work a row against the row above
  std::vector<float> band_work_;   // split's scratch
  int lo_ = kMaxRows, hi_ = 0;     // rows added: lo_..hi_-1
};

}  // namespace gpubridge::sim
