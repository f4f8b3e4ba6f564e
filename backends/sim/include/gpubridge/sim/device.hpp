#pragma once
// The spigpu v1 device model (docs/protocol.md sections 2-13): register file, command FIFO, SPI
// front end (link CRC, strict mode, MEM_DATA prefetch), and the rendering stages behind it.
//
// Two ways in:
//  - as an SPI target (backends::SpiTarget): what the emulated USB bridges drive, frame by frame;
//  - directly: write(Frame) / write(FrameView) / read(index) behave exactly as complete frames
//    arriving on the link (reads feed the link CRC too), memory() exposes video memory.
// The device is single-threaded from the caller's point of view (one caller at a time); with
// options.threads > 1 it rasterises with internal workers and produces identical bytes.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/backends/spi_target.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/sim/options.hpp"

namespace gpubridge::sim {

// Counters of what the device did since construction or reset_stats(); the timing model turns
// them into predicted board cycles. Never used for decisions.
struct DeviceStats {
  std::uint64_t frames_received = 0;      // complete frames (reads and writes)
  std::uint64_t frames_aborted = 0;
  std::uint64_t queued_executed = 0;      // FIFO entries executed
  std::uint64_t triangles_kicked = 0;     // VERTEX writes that formed a triangle
  std::uint64_t triangles_rasterised = 0; // D != 0 and a non-empty clipped bounding box
  std::uint64_t pixels_scanned = 0;       // pixels tested for coverage inside bounding boxes
  std::uint64_t pixels_covered = 0;       // covered pixels (inside the clip rectangle)
  std::uint64_t pixels_depth_passed = 0;  // covered pixels that passed the depth test
  std::uint64_t pixels_textured = 0;      // passed pixels that sampled the texture
  std::uint64_t pixels_blended = 0;       // passed pixels that read the destination colour
  std::uint64_t texel_bytes = 0;          // texture bytes fetched (4 texels per bilinear sample)
  std::uint64_t clear_bytes = 0;          // bytes written by CLEAR / CLEAR_Z
  std::uint64_t mem_data_writes = 0;      // MEM_DATA writes (8 bytes each)
  std::uint64_t swaps = 0;                // scanned-out frames
  // The work a gateware's stages see (docs/protocol.md section 19), by render-state class: the
  // attribute planes a triangle's setup computes and its pixels interpolate. Class index bit 0:
  // Gouraud colour (R, G, B, A), bit 1: depth (Z; test or write), bit 2: textured (S, T, Q); a
  // plane counts only when the colour stage is not fully masked (depth excepted).
  struct ModeWork {
    std::uint64_t triangles = 0;  // triangles rasterised with this class
    std::uint64_t rows = 0;       // rows of their clipped bounding boxes (the rasteriser visits each)
    std::uint64_t columns = 0;    // columns of those boxes (a boundary-following walk crosses them)
    std::uint64_t pixels = 0;     // their covered pixels
    bool operator==(const ModeWork&) const = default;
  };
  static constexpr unsigned kModeClasses = 8;
  std::array<ModeWork, kModeClasses> by_mode{};
  std::uint64_t triangles_rejected = 0;   // set up, then nothing to draw (D = 0 or an empty clipped box)
  std::uint64_t clears = 0;               // CLEAR / CLEAR_Z with a non-empty clipping rectangle
  std::uint64_t clear_rows = 0;           // rows they filled
  std::uint64_t clear_pixels = 0;         // pixels they filled
  // The SDRAM rows the drawn pixels' depth and colour accesses open (timing.hpp SdramRows, the
  // ULX3S controller's geometry, in drawing order): ACTIVEs on an idle bank and row misses
  // (another row of the bank open). Clears leave their rows open but are not counted here.
  // Texture bytes inside the textured triangles' texture-space footprints (at most their samples'
  // bytes): what a texel cache fetches from memory at most, without wrapping.
  std::uint64_t texel_footprint_bytes = 0;
  // Texel reads the ecp5's texel cache makes (timing.hpp TexelCache, replayed per covered pixel of
  // the textured triangles): its misses, which also enter the row stream below between the pixel's
  // depth and colour accesses.
  std::uint64_t texel_fetches = 0;
  std::uint64_t sdram_accesses = 0;  // every access of that stream (a 32-bit word each)
  std::uint64_t row_opens = 0;
  std::uint64_t row_misses = 0;
  std::uint64_t textured_row_misses = 0;  // those of textured triangles (class bit 2)
  // Per triangle of a depth class, its last pixels (at most the depth stage's 4 reads in flight):
  // the memory work the next triangle's setup hides, beside the rows counted above.
  std::uint64_t depth_tail_pixels = 0;
  bool operator==(const DeviceStats&) const = default;
};
// The class index of DeviceStats::by_mode as a name: "flat", "gouraud", "z", "gouraud_z", "tex",
// "tex_gouraud", "tex_z", "tex_gouraud_z".
const char* mode_class_name(unsigned index);

// One covered pixel as the interpolator sees it, before quantisation to the framebuffer
// (render --dump-attributes). Values are the exact rationals N/D of docs/protocol.md section 9
// converted to double, in vertex units: z in 0..2^24-1, r g b a in 0..255, u and v = s/q and t/q
// in texture widths / heights (0 when q = 0). Flat shading reports the flat colour.
struct CoveredPixel {
  int x = 0, y = 0;
  std::uint64_t triangle = 0;  // index of the kicked triangle since reset (0-based)
  double z = 0, r = 0, g = 0, b = 0, a = 0, u = 0, v = 0;
};
using PixelObserver = std::function<void(const CoveredPixel&)>;

class Device final : public backends::SpiTarget {
 public:
  // Validates the options (errors name the bad option) and builds a device in its reset state
  // with zeroed video memory.
  static Result<std::unique_ptr<Device>> create(const DeviceOptions& options);
  ~Device() override;
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  // --- SPI front end (backends::SpiTarget) ---
  std::uint8_t miso_status() override;
  std::uint64_t read_register(std::uint8_t index) override;
  void frame_complete(const protocol::Frame& frame) override;
  void frame_aborted() override;
  bool busy_pin() const override;

  // --- direct API: the same effect as complete frames on the link ---
  // A write frame is validated and queued or acted on (section 5); a read frame (read = true)
  // performs the read (its value is discarded) and feeds the link CRC.
  void write(const protocol::Frame& frame);
  void write(protocol::FrameView frames);
  // A complete read frame: returns the value and feeds the link CRC.
  std::uint64_t read(std::uint8_t index);
  // Executes every released FIFO entry (no-op in untimed mode, where nothing waits).
  void drain();
  // Executes at most n released FIFO entries (time passing without frames on the link, e.g. while
  // a bridge waits for the BUSY pin). Returns how many executed.
  unsigned step(unsigned n);

  // Video memory (vram_bytes). Direct access is the simulator's fast path for uploads and
  // readback; it has the same effect as MEM_ADDR/MEM_DATA writes of the same bytes.
  std::span<std::uint8_t> memory();
  std::span<const std::uint8_t> memory() const;

  // Called for every scanned-out frame (one per executed FB_DISPLAY write), on the caller's thread.
  void set_scanout_callback(backends::ScanoutCallback cb);
  // Called for every covered pixel (slow path: set only to inspect attributes; nullptr to stop).
  void set_pixel_observer(PixelObserver observer);

  const DeviceOptions& options() const;
  std::uint64_t caps() const;  // CAPS register value
  std::uint64_t caps2() const;  // CAPS2 register value (protocol 1.4)
  std::uint64_t id() const;    // ID register value
  std::uint16_t errors() const;  // STATUS.ERRORS
  const DeviceStats& stats() const;
  void reset_stats();

 private:
  struct State;
  explicit Device(std::unique_ptr<State> state);
  std::unique_ptr<State> s_;
};

}  // namespace gpubridge::sim
