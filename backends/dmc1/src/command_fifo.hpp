#pragma once
// The command FIFO between the dispatcher and the column renderer. The dispatcher decodes each
// command word as the span drawer's in_start does (parameters update the registers at once) and
// queues the spans as self-contained jobs: everything a span writes depends only on the job and
// the column buffers, so the renderer can split the rows of every column across threads. The FIFO
// is bounded (jobs and terrain pixels) and never holds more than one frame, so a frame completes
// at the end of a batch.
#include <cstdint>
#include <vector>

#include "gpubridge/dmc1/command.hpp"
#include "gpubridge/dmc1/texture_memory.hpp"

namespace gpubridge::dmc1 {

enum class JobType : std::uint8_t {
  Fill,         // background wall: one entry and one depth for every row
  Wall,         // textured wall: constant u, depth and light; v steps per row
  Plane,        // perspective span through the 1/n table
  Pixels,       // terrain: a precomputed list of (row, depth, texel) writes
  EndOfColumn,  // scan the column out and swap column buffers
};

// A terrain write the event machine produced; it still has to pass the depth test.
struct PixelWrite {
  std::uint8_t row;
  std::uint16_t entry;  // normal mode: (L4 << 12) | texel; lightmap mode: texel (the light byte)
  std::uint32_t dist;
};

struct SpanJob {
  JobType type = JobType::Fill;
  std::uint8_t start = 0, end = 0;  // rows start..end (end <= 239; start may exceed end: no rows)
  bool lightmap = false;            // write only the light byte
  bool background = false;          // texture id 0: texel 99, light 15
  std::uint8_t light = 0;           // L, 0..15
  std::uint16_t column = 0;         // EndOfColumn: the screen column it outputs
  TextureBinding binding;
  std::uint32_t dist = 0;           // Fill, Wall
  std::uint16_t entry = 0;          // Fill: the entry written (normal mode) or the light byte (lightmap)
  std::uint32_t u = 0;              // Wall: texel column
  std::uint32_t v_fixed = 0;        // Wall: v_init << 11
  std::uint32_t v_step = 0;         // Wall: 14-bit increment (11 fractional bits)
  std::int32_t dot_ray = 0, dot_u = 0, dot_v = 0;  // Plane: values at the span start
  std::int32_t ny = 0, uy = 0, vy = 0, ded = 0, u_offset = 0, v_offset = 0;
  std::uint32_t first_write = 0, writes = 0;  // Pixels: range in CommandFifo::writes
};

class CommandFifo {
 public:
  static constexpr std::size_t kMaxJobs = 4096;
  static constexpr std::size_t kMaxWrites = 1u << 18;
  // The most one terrain span can write: its events are bounded by the distance steps and rows.
  static constexpr std::size_t kMaxWritesPerSpan = 2048;

  std::vector<SpanJob> jobs;
  std::vector<PixelWrite> writes;
  unsigned first_buffer = 0;  // draw buffer when the batch started
  bool frame_complete = false;

  // True when the renderer must run before the next command is queued.
  bool full() const { return frame_complete || jobs.size() >= kMaxJobs || writes.size() + kMaxWritesPerSpan > kMaxWrites; }
  bool empty() const { return jobs.empty(); }
  void clear(unsigned buffer) {
    jobs.clear();
    writes.clear();
    first_buffer = buffer;
    frame_complete = false;
  }
};

}  // namespace gpubridge::dmc1
