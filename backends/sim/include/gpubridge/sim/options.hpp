#pragma once
// Run-time options of the simulator: the device it models (memory size, limits, FIFO) and the
// accuracy knobs. Knobs are simulator options, never part of the wire protocol; the defaults are
// the exact hardware behaviour of docs/protocol.md.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::sim {

struct AccuracyKnobs {
  unsigned recip_bits = 10;    // reciprocal table index bits b (section 10.1), 1..16
  unsigned nr_steps = 1;       // Newton-Raphson steps k, 0..4
  unsigned subpixel_bits = 4;  // honoured vertex subpixel bits, 0..4 (fewer: X/Y truncated toward -inf)
  unsigned z_bits = 24;        // honoured depth bits, 1..24 (fewer: Z truncated before test and store)
  // The preview rasteriser (`--accuracy preview`, docs/simulator.md "Preview"): float planes and
  // perspective, several times less exact than the hardware, for previews, remote viewing and CI
  // smoke runs. Coverage stays exact; subpixel_bits and z_bits still apply; the reciprocal knobs
  // do not (there is no table).
  bool preview = false;

  // True when every knob has its hardware value (the simulator is then the golden model).
  bool exact() const {
    return recip_bits == 10 && nr_steps == 1 && subpixel_bits == 4 && z_bits == 24 && !preview;
  }
  friend bool operator==(const AccuracyKnobs&, const AccuracyKnobs&) = default;
};

// Applies one setting: "KNOB=VALUE" ("recip_bits=8", "z_bits=16") or a mode word, "preview" (the
// preview rasteriser) or "exact" (every knob at its hardware value). Errors name the knob, the
// value and the accepted range. The retired knob `fast` is refused with a pointer to preview.
Result<void> apply_knob(AccuracyKnobs& knobs, std::string_view setting);
// Parses a list of settings starting from the defaults.
Result<AccuracyKnobs> parse_knobs(std::span<const std::string> settings);
// "recip_bits=10 nr_steps=1 subpixel_bits=4 z_bits=24"; in preview mode "preview" followed by the
// knobs that differ from the hardware ("preview z_bits=16").
std::string to_string(const AccuracyKnobs& knobs);
// The accuracy a frame is rendered with, as the CLI, the daemon and the viewer name it: "exact",
// "preview" or "knobs" (hardware-precision knobs that differ from the hardware).
std::string accuracy_mode(const AccuracyKnobs& knobs);

// CAPS.FEATURES bits (docs/protocol.md, CAPS).
enum Feature : std::uint8_t {
  FEATURE_BILINEAR = 1u << 0,
  FEATURE_BLEND = 1u << 1,
  FEATURE_DITHER = 1u << 2,
  FEATURE_STRICT_LINK = 1u << 3,
  FEATURE_RGB565 = 1u << 4,
  FEATURE_RGBA2222 = 1u << 5,
  FEATURE_TEMPORAL_DITHER = 1u << 6,  // TRI_MODE.TEMPORAL and DITHER_PHASE (protocol 1.1)
  FEATURE_TEXTURE = 1u << 7,          // TRI_MODE.TEXTURED: the texture unit (protocol 1.2)
};
inline constexpr std::uint8_t kAllFeatures = 0xFF;
// CAPS2.FEATURES2 bits (protocol 1.4, docs/protocol.md, CAPS2); the other bits are reserved.
enum Feature2 : std::uint8_t {
  FEATURE2_DEPTH = 1u << 0,  // the depth buffer: TRI_MODE.Z_TEST / Z_WRITE and CLEAR_Z
};
inline constexpr std::uint8_t kAllFeatures2 = FEATURE2_DEPTH;

inline constexpr std::uint64_t kMaxVramBytes = 1ull << 32;  // addresses are 32-bit
inline constexpr unsigned kMaxThreads = 64;

struct DeviceOptions {
  std::uint64_t vram_bytes = 8u << 20;  // multiple of 1024, 64 KiB .. 4 GiB
  unsigned max_width = protocol::kMaxFramebufferDim;   // CAPS.MAX_WIDTH, 1..1024
  unsigned max_height = protocol::kMaxFramebufferDim;  // CAPS.MAX_HEIGHT, 1..1024
  unsigned fifo_depth = 512;                           // CAPS.FIFO_DEPTH, 64..1023
  std::uint16_t variant = 0;                           // ID.VARIANT (0 = simulator)
  std::uint8_t features = kAllFeatures;                // CAPS.FEATURES
  std::uint8_t features2 = kAllFeatures2;              // CAPS2.FEATURES2 (only kAllFeatures2's bits)
  // 0 = untimed: queued writes execute as soon as they are released (the default).
  // N > 0: each received frame lets at most N FIFO entries execute (a device slower than the
  // link, for flow-control tests); Device::drain() executes the rest.
  unsigned fifo_drain_per_frame = 0;
  // With fifo_drain_per_frame > 0: the drain happens after every fifo_drain_interval-th received
  // frame (1..1024), so N = 1, interval = 4 models a device four times slower than the link.
  unsigned fifo_drain_interval = 1;
  unsigned threads = 1;  // rasteriser worker threads (1 = no pool), 1..kMaxThreads
  // false: every pixel goes through the scalar routines instead of the vector ones. The output is
  // identical by design; tests render both ways and compare bytes.
  bool vector_routines = true;
  // Count the SDRAM rows the draws open (DeviceStats sdram_accesses, row_opens, row_misses,
  // texel_footprint_bytes: the timing model's row and footprint terms, section 19). The count
  // replays every drawn triangle's spans (about as costly as drawing an untextured one), so only
  // what estimates timing turns it on: `gpubridge render --timing`, the frame predictions, the
  // simulator beside the gateware (rtl::simulator_options); otherwise those counters stay 0.
  bool sdram_rows = false;
  AccuracyKnobs accuracy;

  // Empty when valid, otherwise what is wrong and the accepted range.
  Result<void> validate() const;
};

}  // namespace gpubridge::sim
