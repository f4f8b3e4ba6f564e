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
// a triangle then counts all of its work on one side, as often the one as the other.
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
  // about 22 instructions a pixel in the span routine, 300 a row in the row loop, 1,500 a Kernel).
  static constexpr std::int64_t kRowWork = 14, kTriangleWork = 70;

  static constexpr int kBands = kMaxRows / kBandRows;
  // add() indexes work_ by a triangle's middle row: every framebuffer the options accept must fit.
  static_assert(kMaxRows >= static_cast<int>(protocol::kMaxFramebufferDim),
                "BandSplit's table must cover the tallest framebuffer");

  // A triangle of rows y0..y1-1 (0 <= y0 < y1 <= kMaxRows) and twice its area `den` in 1/16 px
  // units (so den is its area in 1/512 px, the estimate's unit).
  void add(int y0, int y1, std::int64_t den) {
    work_[static_cast<std::size_t>((y0 + y1) >> 1) / kBandRows] += den + ((kTriangleWork + kRowWork * (y1 - y0)) << 9);
  }

  // cuts[0..n]: worker w draws rows cuts[w]..cuts[w+1]-1 (cuts[0] = 0, cuts[n] = kMaxRows), whole
  // bands each, the estimated work as even as whole bands allow. Clears the estimate.
  void split(unsigned n, std::vector<int>& cuts) {
    cuts.assign(n + 1, 0);
    cuts[n] = kMaxRows;
    std::int64_t total = 0;
    for (std::int64_t w : work_) total += w;
    // Cut k after the band where the running sum comes nearest k·total/n (nothing added: every
    // row to worker 0).
    std::int64_t sum = 0;
    std::size_t b = 0;
    for (unsigned k = 1; k < n; ++k) {
      const double target = static_cast<double>(total) * k / n;
      while (b < work_.size() && static_cast<double>(sum) + 0.5 * static_cast<double>(work_[b]) < target) sum += work_[b++];
      cuts[k] = total == 0 ? kMaxRows : static_cast<int>(b) * kBandRows;
    }
    work_.fill(0);
  }

 private:
  std::array<std::int64_t, kBands> work_{};  // per band: the work of the triangles whose middle row is in it
};

}  // namespace gpubridge::sim
