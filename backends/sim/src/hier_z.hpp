#pragma once
// A coarse depth bound for rejecting occluded spans without reading the depth buffer (issue 17,
// random-Z scenes): per block of 16 rows × 32 pixels, an upper bound of the 24-bit depths stored
// in it. A span whose smallest depth is not below its blocks' bounds (LESS; not at or below for
// LEQUAL) fails the test at every pixel and is skipped; its pixels are still counted as scanned
// and covered, so bytes, errors and DeviceStats stay those of drawing it. The exact kernel asks
// a triangle's whole 16-row bands the same way first (rasterizer.cpp, band_occluded), with a
// lower bound of the triangle's depth over the band's rows; the preview's plain kernel too
// (preview_plain_kernel.inc, band_occluded: the least of its spans' depths in its own integers).
//
// Why the bound stays exact without watching every write to memory: a bound is only used within
// one generation, which the renderer ends at every flush() (anything that reads or writes memory
// outside the rasteriser flushes first) and at every change of render state. A block's bound is
// read from memory the first time it is needed in a generation, and inside a generation the only
// writes are the rasteriser's under one state whose depth test is LESS or LEQUAL with disjoint
// buffers in VRAM: every depth written is below the one it replaces, so the bound can only become
// loose, never wrong. A block written since its bound was read is read again the next time a
// later triangle asks (while the triangle that wrote it keeps the loose bound), which keeps the
// bounds tight enough to reject. Blocks lie inside one 16-row band, so with worker threads each
// block is only touched by the worker owning its band.
#include <cstdint>
#include <vector>

namespace gpubridge::sim {

// The largest 24-bit depth (big-endian words, top byte ignored) of `rows` rows of `cols` words
// from `z`, `pitch` bytes apart.
std::uint32_t depth_block_max(const std::uint8_t* z, std::size_t pitch, unsigned rows, unsigned cols);

class HierZ {
 public:
  static constexpr int kRowsLog = 4, kColsLog = 5;  // 16 × 32 pixels

  // How a run of rows asks the bounds (the exact and the preview kernels alike). A run stops asking
  // after kTries rows in a row that they did not reject: in front-to-back scenes no row is rejected,
  // and asking on every row cost about 200 instructions a row (1,000-px triangles, callgrind).
  static constexpr unsigned kTries = 2;
  // A new 16-row band of blocks gives the run its tries afresh when the bounds rejected rows in
  // this run so far, or every fourth band (large random-Z triangles: visible at one end, hidden at
  // the other; front-to-back ones are never rejected and ask only every fourth band).
  static bool band_asks_afresh(int band, bool rejected) { return rejected || (band & 3) == 0; }
  // The next run's number from the context's counter (0 means "not written" in a block).
  static std::uint32_t next_run(std::uint32_t& counter) {
    const std::uint32_t run = ++counter;
    return run != 0 ? run : ++counter;
  }

  // Sizes the grid for a width × height buffer. Call while no worker draws.
  void prepare(unsigned width, unsigned height) {
    if (width == width_ && height == height_) return;
    width_ = width;
    height_ = height;
    per_row_ = (width + (1u << kColsLog) - 1) >> kColsLog;
    const std::size_t bands = (height + (1u << kRowsLog) - 1) >> kRowsLog;
    const std::size_t n = std::size_t{per_row_} * bands;
    if (blocks_.size() < n) blocks_.resize(n);
    if (bands_.size() < bands) bands_.resize(bands);
  }

  // Whether a triangle's rows in 16-row band `band` are worth asking as a whole (the exact and the
  // preview kernels' band tests, before their rows are asked one by one). After kBandMisses band tests in a row in this
  // band that did not reject, only every 2nd, 4th … 16th is asked: front-to-back scenes are never
  // rejected and would pay a test a band for nothing. Kept per band, which one worker owns, so
  // the workers share nothing here and the answers follow submission order at any thread count
  // (a heuristic only: asking or not changes no byte).
  bool band_worth_asking(int band) {
    Band& b = bands_[static_cast<std::size_t>(band)];
    if (b.skip == 0) return true;
    --b.skip;
    return false;
  }
  void band_answered(int band, bool rejected) {
    Band& b = bands_[static_cast<std::size_t>(band)];
    if (rejected) {
      b.misses = 0;
      return;
    }
    if (b.misses < kBandMisses + 4) ++b.misses;
    if (b.misses >= kBandMisses) b.skip = static_cast<std::uint8_t>((2u << (b.misses - kBandMisses)) - 1);
  }

  // Whether every stored depth of row y's pixels xa..xb (inclusive) is at most `bound` (<= for
  // LEQUAL tests: `strict` false; < for LESS: `strict` true, where a depth equal to the stored one
  // also fails), in generation `gen`, asked by Kernel run `run` (its own writes do not make it
  // read a block again). A block written since its bound was read is read again only when the
  // old bound does not answer, and after reads that did not reject, only every 2^level-th time
  // (front-to-back scenes write every block and are never rejected: their rows would read their
  // blocks for nothing).
  bool occludes(const std::uint8_t* zbuf, int y, int xa, int xb, std::uint32_t z, bool strict, std::uint64_t gen,
                std::uint32_t run) {
    const int by = y >> kRowsLog, bx = xa >> kColsLog, n = (xb >> kColsLog) - bx;
    Block* b = &blocks_[static_cast<std::size_t>(by) * per_row_ + static_cast<unsigned>(bx)];
    std::uint32_t m = 0;
    bool stale = false;
    for (int i = 0; i <= n; ++i) {
      Block& k = b[i];
      if (k.gen != gen) refresh(k, zbuf, by, bx + i, gen);
      m = k.max > m ? k.max : m;
      stale |= k.written != 0 && k.written != run;
    }
    if (strict ? z >= m : z > m) return true;
    if (!stale) return false;
    std::uint64_t read = 0;  // blocks read again (the first 64: spans are rarely wider than 2,048 pixels)
    for (int i = 0; i <= n; ++i) {
      Block& k = b[i];
      if (k.written == 0 || k.written == run) continue;
      if (k.skip != 0) {
        --k.skip;
        continue;
      }
      refresh(k, zbuf, by, bx + i, gen);
      read |= i < 64 ? std::uint64_t{1} << i : 0;
    }
    if (read == 0) return false;
    m = 0;
    for (int i = 0; i <= n; ++i) m = b[i].max > m ? b[i].max : m;
    const bool occluded = strict ? z >= m : z > m;
    for (int i = 0; i <= n && i < 64; ++i) {
      if (!((read >> i) & 1)) continue;
      Block& k = b[i];
      k.level = occluded ? 0 : static_cast<std::uint8_t>(k.level < kMaxLevel ? k.level + 1 : kMaxLevel);
      k.skip = static_cast<std::uint8_t>((1u << k.level) - 1);
    }
    return occluded;
  }
  // Run `run` may have written rows ya..yz-1 (exclusive end) of columns xa..xb (inclusive).
  void mark(int ya, int yz, int xa, int xb, std::uint32_t run) {
    for (int by = ya >> kRowsLog; by <= (yz - 1) >> kRowsLog; ++by) {
      Block* b = &blocks_[static_cast<std::size_t>(by) * per_row_];
      for (int bx = xa >> kColsLog; bx <= xb >> kColsLog; ++bx) b[bx].written = run;
    }
  }

 private:
  static constexpr unsigned kMaxLevel = 6;
  static constexpr unsigned kBandMisses = 8;
  // One cache line a band: neighbouring bands belong to different workers, which update these on
  // every band test (2-byte records side by side bounced one line between the cores).
  struct alignas(64) Band {
    std::uint8_t misses = 0;  // band tests in a row that did not reject (capped)
    std::uint8_t skip = 0;    // band tests to let pass before asking again
  };
  struct Block {
    std::uint64_t gen = 0;      // generation the bound was read in (0: never)
    std::uint32_t max = 0;      // upper bound of the block's depths
    std::uint32_t written = 0;  // the run that last wrote into it since the bound was read (0: none)
    std::uint8_t level = 0;     // reads in a row that did not reject (capped at kMaxLevel)
    std::uint8_t skip = 0;      // stale answers to give before reading it again
  };
  void refresh(Block& k, const std::uint8_t* zbuf, int by, int bx, std::uint64_t gen) const {
    const unsigned y0 = static_cast<unsigned>(by) << kRowsLog, x0 = static_cast<unsigned>(bx) << kColsLog;
    const unsigned rows = height_ - y0 < (1u << kRowsLog) ? height_ - y0 : 1u << kRowsLog;
    const unsigned cols = width_ - x0 < (1u << kColsLog) ? width_ - x0 : 1u << kColsLog;
    const std::size_t pitch = std::size_t{width_} * 4;
    k.max = depth_block_max(zbuf + y0 * pitch + std::size_t{x0} * 4, pitch, rows, cols);
    k.gen = gen;
    k.written = 0;
  }

  unsigned width_ = 0, height_ = 0, per_row_ = 0;
  std::vector<Block> blocks_;
  std::vector<Band> bands_;
};

}  // namespace gpubridge::sim
