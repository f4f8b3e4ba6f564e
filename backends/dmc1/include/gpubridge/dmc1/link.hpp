#pragma once
// A command link in front of the DMC-1 (docs/dmc1.md, "UART link"): words arrive at the link's
// byte rate into the standalone SOC's 256-entry command FIFO, which nothing flow-controls. The
// estimate runs the stream through the DMC-1's timing model with each command's arrival time:
// frames per second end to end, whether the link or the GPU sets the pace, and how full the FIFO
// gets (above its depth, commands are lost on the real board).
#include <cstdint>
#include <memory>
#include <span>

#include "gpubridge/common/result.hpp"
#include "gpubridge/dmc1/texture_memory.hpp"
#include "gpubridge/dmc1/timing.hpp"

namespace gpubridge::dmc1 {

inline constexpr unsigned kStandaloneFifoDepth = 256;

struct LinkEstimate {
  double baud = 0;
  std::uint64_t frames = 0;
  double seconds = 0;           // first byte to the end of the last frame
  double frames_per_second = 0;
  double gpu_busy = 0;          // fraction of the time the GPU had work
  unsigned max_fifo = 0;        // most commands waiting in the FIFO
  bool overflow = false;        // max_fifo exceeded the FIFO depth: the board would lose commands
};

// bits_per_byte: 10 for 8N1.
Result<LinkEstimate> estimate_link(std::span<const std::uint64_t> words, double baud, std::shared_ptr<const TextureMemory> textures,
                                   const TimingParameters& timing = {}, unsigned fifo_depth = kStandaloneFifoDepth,
                                   unsigned bits_per_byte = 10);
// The fastest baud rate (to 1%) at which the FIFO never overflows on this stream; 0 when even the
// slowest rate tried overflows (it cannot: at a low enough rate the FIFO stays empty).
Result<double> fastest_lossless_baud(std::span<const std::uint64_t> words, std::shared_ptr<const TextureMemory> textures,
                                     const TimingParameters& timing = {}, unsigned fifo_depth = kStandaloneFifoDepth);

}  // namespace gpubridge::dmc1
