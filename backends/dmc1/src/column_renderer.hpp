#pragma once
// The column renderer: draws the command FIFO's spans into the column buffers and scans every
// finished column out into the screen. Rows are independent (a span's texels never depend on the
// buffers), so each worker owns a band of rows of every column; the result is the same for any
// number of workers.
#include <cstdint>
#include <memory>

#include "column_buffers.hpp"
#include "command_fifo.hpp"
#include "gpubridge/common/band_pool.hpp"
#include "gpubridge/dmc1/scanout.hpp"
#include "gpubridge/dmc1/texture_memory.hpp"

namespace gpubridge::dmc1 {

class ColumnRenderer {
 public:
  ColumnRenderer(std::shared_ptr<const TextureMemory> textures, unsigned threads);
  unsigned threads() const { return pool_.workers(); }
  // screen: kColumns * kRows words, column-major.
  void run(const CommandFifo& fifo, ColumnBuffers& buffers, const Scanout& scanout, std::uint16_t* screen);

 private:
  struct Band;
  std::shared_ptr<const TextureMemory> textures_;
  BandPool pool_;
};

}  // namespace gpubridge::dmc1
