#pragma once
// The timing model (docs/protocol.md section 19): predicted board time for a piece of work
// (usually one scanned-out frame), from the device's counters and a board profile, plus the SPI
// time of the frames that carried it. Not part of the device contract; the simulator never
// sleeps or stalls because of it.
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/sim/device.hpp"

namespace gpubridge::sim {

struct BoardTiming {
  std::string name = "ecp5-50mhz";
  double clock_mhz = 50.0;              // core clock
  double cycles_per_command = 1.0;      // every executed FIFO entry (register decode)
  double cycles_per_triangle = 24.0;    // setup: D, edges, bias, attribute planes
  double cycles_per_scanned_pixel = 0.25;  // coverage test (4 pixels per clock)
  double cycles_per_pixel = 1.0;        // depth test/write + colour store, per passed pixel
  double cycles_per_textured_pixel = 2.0;  // extra: reciprocal + fetch + combine
  double cycles_per_blended_pixel = 1.0;   // extra: destination read + blend
  double clear_bytes_per_cycle = 8.0;
  double memory_bytes_per_cycle = 4.0;  // external memory bandwidth (SDRAM 16 bit, DDR)
  double spi_clock_mhz = 40.0;
  double cs_gap_us = 1.0;               // chip-select high time between bursts
  unsigned frames_per_burst = 32;       // flow-control group size
  // The gateware's structure (0 in the default profile; the presets "up5k" and "ecp5" use them),
  // per render-state class of DeviceStats::by_mode (index bit 0 Gouraud, 1 depth, 2 textured):
  // setup cycles per triangle (the planes it computes), rasteriser cycles per bounding-box row
  // (entering and leaving the row), per bounding-box column (the walk along the boundary to the
  // next row's span) and per covered pixel (steppers, depth read, memory).
  std::array<double, DeviceStats::kModeClasses> setup_cycles{};
  std::array<double, DeviceStats::kModeClasses> row_cycles{};
  std::array<double, DeviceStats::kModeClasses> column_cycles{};
  std::array<double, DeviceStats::kModeClasses> pixel_cycles{};
  double cycles_per_rejected_triangle = 0;  // setup that finds D = 0 or an empty box
  double cycles_per_clear = 0;              // start of a CLEAR / CLEAR_Z (up5k: its rectangle's setup)
  double cycles_per_clear_row = 0;
  double cycles_per_clear_pixel = 0;
  double cycles_per_mem_write = 0;          // MEM_DATA write (8 bytes through the arbiter)
  double cycles_per_texel_byte = 0;         // texture bytes fetched (bilinear: four texels a sample)
  double cycles_per_color_byte = 0;         // colour bytes written (bpp per passed pixel)
  // The SDRAM's rows (the ecp5 preset; 0 elsewhere): cycles per access of the row model's stream
  // (DeviceStats::sdram_accesses: a 32-bit word, a burst of 2), per ACTIVE on an idle bank
  // (DeviceStats::row_opens: tRCD), per row miss (row_misses: PRECHARGE + ACTIVE, tRP + tRCD and
  // the bank's tRAS / tWR / tRC waits), and the auto refresh: every refresh_interval_cycles (tREFI
  // in core clocks; 0 = none) the controller spends cycles_per_refresh (precharge all, tRFC, the
  // rows opened again after it), which stretches the rest by 1 / (1 − cycles_per_refresh /
  // refresh_interval_cycles).
  double cycles_per_sdram_access = 0;
  double cycles_per_texel_footprint_byte = 0;  // DeviceStats::texel_footprint_bytes: texel cache fills
  double cycles_per_texel_fetch = 0;           // DeviceStats::texel_fetches: texel cache misses (a word read each)
  double cycles_per_row_open = 0;
  double cycles_per_row_miss = 0;           // a row miss of an untextured draw
  double cycles_per_textured_row_miss = 0;  // of a textured draw (DeviceStats::textured_row_misses)
  // A depth write (a passed pixel of a draw with a depth class: Z_WRITE stores only what passes),
  // beside the per-covered-pixel terms of its class.
  double cycles_per_depth_write = 0;
  // A credit per pixel left in the depth stage when a depth-class triangle's walk ends
  // (DeviceStats::depth_tail_pixels): its memory work, which the per-pixel terms charge, drains
  // under the next triangle's setup. Subtracted.
  double drained_cycles_per_tail_pixel = 0;
  double refresh_interval_cycles = 0;
  double cycles_per_refresh = 0;
  // true: cycles = max(pipeline, bytes / memory_bytes_per_cycle). false: the pipeline terms
  // already hold the memory's time (the gateware presets, fitted on the RTL with its SDRAM and
  // texel cache, which the byte count does not see); memory_cycles is then only reported.
  bool memory_bound = true;
};

// Which row each bank of an SDR SDRAM holds, as a controller that keeps every bank's row open
// until another row of that bank (or a refresh) needs it: the gateware's sdram_ctrl.v. A byte
// address maps to its row like the controller's word address does: the low row_bits of the address
// inside a row (1 KiB: 256 words of 4 bytes), then bank_bits of bank, then the row, so consecutive
// rows rotate through the banks. Each access is a hit (the bank holds its row), an open (the bank
// is idle: ACTIVE) or a miss (the bank holds another row: PRECHARGE + ACTIVE).
struct SdramGeometry {
  unsigned row_bits = 10;  // log2 of the bytes a row holds (ULX3S: 512 columns x 16 bits)
  unsigned bank_bits = 2;  // log2 of the banks (4)
};

class SdramRows {
 public:
  enum class Outcome { Hit, Open, Miss };
  explicit SdramRows(SdramGeometry g = {}) : g_(g), open_(std::size_t{1} << g.bank_bits, kClosed) {}
  // `count` accesses in a row to the row holding byte `address`: the first one's outcome (the
  // others hit), counted.
  Outcome access(std::uint64_t address, std::uint64_t count = 1);
  // The row holding `address` opened without counting (traffic the model does not charge here,
  // e.g. a clear, which has terms of its own, still leaves its rows open).
  void touch(std::uint64_t address);
  // Every row of [address, address + bytes) touched in address order.
  void touch_range(std::uint64_t address, std::uint64_t bytes);
  // An auto refresh: every bank precharged.
  void refresh();
  std::uint64_t hits() const { return hits_; }
  std::uint64_t opens() const { return opens_; }
  std::uint64_t misses() const { return misses_; }
  // The misses of textured draws, counted apart (set_textured): the texture unit's latency is
  // already waited for there, and hides part of a miss.
  std::uint64_t textured_misses() const { return textured_misses_; }
  void set_textured(bool textured) { textured_ = textured; }
  void reset_counts() { hits_ = opens_ = misses_ = textured_misses_ = 0; }
  const SdramGeometry& geometry() const { return g_; }

 private:
  static constexpr std::uint64_t kClosed = ~std::uint64_t{0};
  SdramGeometry g_;
  std::vector<std::uint64_t> open_;  // row per bank, kClosed when precharged
  std::uint64_t hits_ = 0, opens_ = 0, misses_ = 0, textured_misses_ = 0;
  bool textured_ = false;
};

// Accesses gathered into runs of one row before they reach SdramRows::access(address, count):
// consecutive accesses to one row are one outcome and hits.
class RowRunEmitter {
 public:
  explicit RowRunEmitter(SdramRows& rows) : rows_(rows), row_bits_(rows.geometry().row_bits) {}
  ~RowRunEmitter() { flush(); }
  RowRunEmitter(const RowRunEmitter&) = delete;
  RowRunEmitter& operator=(const RowRunEmitter&) = delete;
  // `count` accesses to the row holding byte `address`
  void emit(std::uint64_t address, std::uint64_t count) {
    if (count == 0) return;
    if (count_ != 0 && (address >> row_bits_) == (address_ >> row_bits_)) {
      count_ += count;
      return;
    }
    flush();
    address_ = address;
    count_ = count;
  }
  void flush() {
    if (count_ != 0) rows_.access(address_, count_);
    count_ = 0;
  }

 private:
  SdramRows& rows_;
  unsigned row_bits_;
  std::uint64_t address_ = 0, count_ = 0;
};

// The ecp5 core's texel cache (core_texture.v): four banks by texel parity ({j & 1, i & 1}), each
// holding one word for each texel of eight texel rows of any width up to 1024 (entry {j bits 2:1,
// i bits 9:1}, tag j >> 3): direct mapped, so the rows a span samples are still there when the walk
// comes back on the next row, and a ninth row evicts the first. It is kept across consecutive
// textured triangles with the same texture and buffers (the draw's signature) and forgotten
// otherwise. A miss is a texel read from memory (one 32-bit word), which the row model sees.
class TexelCache {
 public:
  // A textured draw with `signature` (texture base and format, buffers) starts: a different one
  // forgets every texel.
  void begin(std::uint64_t signature) {
    if (entry_.empty()) entry_.assign(kEntries, 0);  // only a device that estimates timing pays for it
    if (!valid_ || signature != signature_) invalidate();
    signature_ = signature;
    valid_ = true;
  }
  // Anything but a textured triangle of the same draw (a clear, an untextured triangle).
  void invalidate() {
    valid_ = false;
    if (++epoch_ == kEpochs) {  // wrapped: no entry of an older epoch may look current
      std::fill(entry_.begin(), entry_.end(), 0);
      epoch_ = 1;
    }
  }
  // Texel (i, j) (wrapped indices, below 1024) of the draw begun: true when held; a miss fills its entry.
  bool lookup(unsigned i, unsigned j) {
    const std::size_t bank = ((j & 1u) << 1) | (i & 1u);
    const std::size_t index = bank << 11 | ((j >> 1) & 3u) << 9 | ((i >> 1) & 511u);
    const std::uint32_t want = epoch_ << 8 | ((j >> 3) & 127u);
    if (entry_.empty()) entry_.assign(kEntries, 0);
    if (entry_[index] == want) {
      ++hits_;
      return true;
    }
    entry_[index] = want;
    ++misses_;
    return false;
  }
  std::uint64_t hits() const { return hits_; }
  std::uint64_t misses() const { return misses_; }
  void reset_counts() { hits_ = misses_ = 0; }

 private:
  static constexpr std::size_t kEntries = 4 * 2048;
  static constexpr std::uint32_t kEpochs = 1u << 24;  // epoch << 8 fits 32 bits
  std::vector<std::uint32_t> entry_;  // epoch << 8 | tag; epoch 0 is never current
  std::uint32_t epoch_ = 1;
  std::uint64_t signature_ = 0;
  bool valid_ = false;
  std::uint64_t hits_ = 0, misses_ = 0;
};

// One span of covered pixels as the ecp5 core's memory port sends it (core_memport.v): per pixel a
// depth read (Z test) and write (Z write) of its 4-byte word, a colour read (blend, partial write
// mask) and write per 32-bit colour word (the write combiner merges the pixels of a word), in pixel
// order: the rows are visited in runs, so a depth and a colour buffer in one bank but different
// rows miss at every switch, and in different banks hit.
struct SpanAccess {
  std::uint64_t color = 0;  // byte address of the first pixel's colour
  std::uint64_t depth = 0;  // byte address of the first pixel's Z word
  unsigned bpp = 4;
  unsigned pixels = 0;
  bool z_read = false, z_write = false, color_read = false, color_write = true;
};
void access_span(SdramRows& rows, const SpanAccess& span);

struct TimingEstimate {
  double pipeline_cycles = 0;  // setup + rasterisation + pixel stages + clears
  double memory_cycles = 0;    // bytes moved / memory_bytes_per_cycle
  double board_cycles = 0;     // max(pipeline, memory): the stages overlap memory traffic
  double board_ms = 0;
  double spi_ms = 0;           // link time of the frames received
  double frame_ms = 0;         // max(board, spi): the slower side sets the frame time
  double fps = 0;
  std::uint64_t memory_bytes = 0;
};

// Counters of `work` (e.g. the difference of two DeviceStats snapshots) under profile `board`;
// color_bpp (bytes per pixel of the colour buffer) sizes the colour traffic; without a depth
// buffer (depth_buffer false: a program drawing in painter's order) covered pixels move no depth bytes.
TimingEstimate estimate_timing(const DeviceStats& work, const BoardTiming& board, unsigned color_bpp,
                               bool depth_buffer = true);
// Link time (ms) of `frames` 72-bit SPI frames under `board`: the bits at its SPI clock plus the
// chip-select gap between bursts of frames_per_burst (docs/protocol.md section 19).
double spi_link_ms(double frames, const BoardTiming& board);
// Passed pixels of the depth classes (DeviceStats::by_mode bit 1): the Z writes of draws that
// write what they test, as the calibration frames and the scenes do.
std::uint64_t depth_writes(const DeviceStats& work);
// The factor the auto refresh stretches a board's work by (1 without refresh terms).
double refresh_stretch(const BoardTiming& board);
// a − b, field by field.
DeviceStats stats_difference(const DeviceStats& a, const DeviceStats& b);
// "clock_mhz=25 spi_clock_mhz=10 ..." settings applied to a profile (errors name the key);
// "profile=NAME" replaces every value with a preset's. The per-class parameters are
// setup_cycles_CLASS, row_cycles_CLASS, column_cycles_CLASS and pixel_cycles_CLASS (CLASS: mode_class_name()).
Result<void> apply_timing_setting(BoardTiming& board, std::string_view setting);
// Named profiles: "ecp5-50mhz" (the default above, an estimate), and "up5k" / "ecp5": the gateware
// profiles (gateware/rtl/spigpu_top.v) at their co-simulated clocks, calibrated on the RTL's cycles
// per frame of every example and scene (`gpubridge bench rtl --fit`, docs/gateware.md).
Result<BoardTiming> timing_preset(std::string_view name);

}  // namespace gpubridge::sim
