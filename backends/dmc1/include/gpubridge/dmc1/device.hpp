#pragma once
// The bit-exact DMC-1 (sylefeb/tinygpus, docs/dmc1.md): command words in, 320 x 240 RGB565 frames
// out, exactly as the RTL's column sender emits them. Stages, named after the hardware:
//   dispatcher (command decode, parameters, span setup, the terrain event machine)
//   -> command FIFO (decoded spans, bounded)
//   -> column renderer (walls, planes, terrain writes, background fills, the lightmap pass; the
//      one-column depth buffer with its buffer tag; rows split across threads)
//   -> column buffers (two 256-entry {light8, index8} columns, never cleared)
//   -> scan-out (palette and light to RGB565) into the screen, one frame per 320 end-of-column commands.
// Output is identical for every thread count.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/dmc1/command.hpp"
#include "gpubridge/dmc1/palette.hpp"
#include "gpubridge/dmc1/texture_memory.hpp"
#include "gpubridge/dmc1/timing.hpp"

namespace gpubridge::dmc1 {

inline constexpr std::size_t kFramePixels = std::size_t{kColumns} * kRows;

struct DeviceOptions {
  unsigned threads = 1;  // 1..64; rows of each column are split across them
  TimingParameters timing;
};

// A completed frame in the GPU's output order: column 0 rows 0..239, then column 1, ... (word i is
// column i / 240, row i % 240; row 0 is the bottom of the screen in the demos' convention). The
// pixels are the device's screen: valid during the callback only; copy what you keep.
struct Frame {
  std::uint32_t number = 0;
  std::span<const std::uint16_t> rgb565;  // kFramePixels words, {r5, g6, b5}
  std::uint64_t gpu_cycles = 0;           // predicted by the timing model
};
using FrameCallback = std::function<void(const Frame&)>;

struct DeviceStats {
  std::uint64_t commands = 0;
  std::uint64_t walls = 0, planes = 0, terrains = 0, backgrounds = 0;  // spans drawn (background = texture-0 wall)
  std::uint64_t parameters = 0, dropped_spans = 0, columns = 0, frames = 0;
  std::uint64_t texture_binds = 0;
  std::uint64_t row_events = 0;  // span drawer events (n + 2 per wall or plane, terrain machine events)
};

class Device {
 public:
  static Result<std::unique_ptr<Device>> create(const DeviceOptions& options, std::shared_ptr<const TextureMemory> textures,
                                                const Palette& palette);
  ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  // Runs command words in order. Every 64-bit word is a valid command, so this cannot fail;
  // frames are delivered to the callback as their 320th column completes.
  void submit(std::span<const std::uint64_t> words);
  // Draws every queued span (columns already sent are in screen() at once; the rest of the queue
  // would otherwise wait for the next batch).
  void flush();
  // Back to the reset state: registers, column and depth buffers zero, draw buffer 0, column 0.
  // The screen keeps its pixels (it is the panel's memory, not the GPU's).
  void reset();

  void set_frame_callback(FrameCallback cb);
  // What the panel shows: every column as last sent, in frame order (kFramePixels words).
  std::span<const std::uint16_t> screen() const;
  // Column the next end-of-column command sends (0..319).
  unsigned column() const;
  const DeviceStats& stats() const;
  const TimingModel& timing() const;
  // Height sample latched by the last terrain span with the pick bit (the SOC's user_data 23:16).
  std::uint8_t picked_height() const;
  unsigned threads() const;

 private:
  struct Impl;
  explicit Device(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// A frame in screen order, as a FRAME message carries it (docs/protocol.md 17.3): rows top to bottom
// (x = column, y = 239 - row: the DMC-1's row 0 is the bottom), each pixel big-endian RGB565. Words
// a short buffer lacks are black.
std::vector<std::uint8_t> frame_rows_rgb565(std::span<const std::uint16_t> column_major);
// The picture of a frame (docs/dmc1.md, "Images"): those rows with 8-bit channels by bit
// replication (image_from_device), opaque.
Image frame_image(std::span<const std::uint16_t> rgb565);

}  // namespace gpubridge::dmc1
