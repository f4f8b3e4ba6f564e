#pragma once
// How an example fits the device it is given (issue 22). Each example says what it would like
// (Wants: framebuffer size and format, double buffering, a depth buffer, its textures, the
// features it uses) and which of those matter most to its seed's idea; fit() reads the device's
// CAPS (video memory, largest framebuffer, FEATURES) and picks the closest configuration that
// fits, giving up first what matters least. The choice is a Fit: what setup() and frame() follow,
// printed by gpubridge-demo (--json too) with everything that was given up and why.
//
// Memory is shared out exactly as draw::Context will place it (the same allocator, dry-run):
// colour buffer(s), depth buffer, then the textures. When memory is short the example's knobs are
// given up in lexicographic order of its `keep` list: the first knob is held longest, the last is
// given up first. Features the device lacks are never used; the example draws its fallback
// instead (painter's order for a missing depth buffer, opaque water without BLEND, ...).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/draw/context.hpp"
#include "gpubridge/sim/options.hpp"

namespace gpubridge::examples {

// Features an example may use: the CAPS.FEATURES bits, texturing (the texture unit) among them as
// bit 7 since protocol 1.2 (a device without it, or --without texture, is handled like any other
// missing feature).
inline constexpr std::uint16_t kBilinear = sim::FEATURE_BILINEAR;
inline constexpr std::uint16_t kBlend = sim::FEATURE_BLEND;
inline constexpr std::uint16_t kDither = sim::FEATURE_DITHER;
inline constexpr std::uint16_t kStrictLink = sim::FEATURE_STRICT_LINK;
inline constexpr std::uint16_t kRgb565 = sim::FEATURE_RGB565;
inline constexpr std::uint16_t kRgba2222 = sim::FEATURE_RGBA2222;
inline constexpr std::uint16_t kTemporalDither = sim::FEATURE_TEMPORAL_DITHER;
// texturing is CAPS.FEATURES bit 7 since protocol 1.2; every 1.0 and 1.1 device (ID.MINOR < 2) textures
inline constexpr std::uint16_t kTexturing = sim::FEATURE_TEXTURE;
// The depth buffer is CAPS2.FEATURES2 bit 0 since protocol 1.4 (protocol::has_depth_buffer: every
// 1.0 ... 1.3 device has one); here bit 8, above the CAPS.FEATURES byte. Without it the examples
// draw in painter's order, as they do when video memory is short.
inline constexpr std::uint16_t kDepthBuffer = static_cast<std::uint16_t>(sim::FEATURE2_DEPTH << 8);
// "bilinear", "blend", "dither", "rgb565", "rgba2222", "temporal", "texture", "depth".
std::string_view feature_name(std::uint16_t bit);
std::optional<std::uint16_t> parse_feature(std::string_view name);
// "bilinear blend ..." for a mask (the known bits only).
std::string feature_names(std::uint16_t mask);

// What the examples need to know of a device.
struct DeviceCaps {
  std::string name = "simulator";  // board profile name, or "simulator"
  std::uint64_t vram_bytes = 8u << 20;
  unsigned max_width = protocol::kMaxFramebufferDim, max_height = protocol::kMaxFramebufferDim;
  std::uint16_t features = sim::kAllFeatures | kTexturing | kDepthBuffer;
  bool has(std::uint16_t bit) const { return (features & bit) == bit; }

  // From a device description (a backend's info(), a daemon's WELCOME): limits, the CAPS
  // register's FEATURES and CAPS2's depth buffer; a description without CAPS (0) is taken to have
  // every feature.
  static DeviceCaps from(const backends::DeviceInfo& info);
  // The simulator options of a device with these CAPS (to render it in-process).
  sim::DeviceOptions simulator_options() const;
};

// What the command line forces (gpubridge-demo --size, --format, --no-depth, --without).
struct FitRequest {
  std::optional<std::pair<unsigned, unsigned>> size;
  std::optional<protocol::PixelFormat> format;
  bool no_depth = false;
  std::uint16_t without = 0;  // features not to use even when the device has them
};
// "320x240" → (320, 240); errors say what was expected.
Result<std::pair<unsigned, unsigned>> parse_size(std::string_view text);

struct TextureWant {
  std::string name;
  unsigned width = 0, height = 0;  // powers of two
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  bool bilinear = false;
};

struct TextureFit {
  std::string name;
  unsigned width = 0, height = 0;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  bool bilinear = false;
  // The image an example made at the wanted size, box-filtered down to this size.
  Image shrink(const Image& full) const;
  draw::TextureOptions options(protocol::Wrap wrap_s = protocol::Wrap::Repeat,
                               protocol::Wrap wrap_t = protocol::Wrap::Repeat) const;
};

// The memory knobs, in the words of Wants::keep.
enum class Knob : std::uint8_t { Size, Format, Textures, DoubleBuffer, Depth };

struct Wants {
  unsigned width = 320, height = 240;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  bool depth = true;          // a depth buffer (without one the example draws in painter's order)
  bool double_buffer = true;
  bool dither = false;        // Bayer dither at its own format (otherwise only when the format is reduced)
  std::vector<TextureWant> textures;
  // Most important first; memory shortage gives up the last one first.
  std::array<Knob, 5> keep = {Knob::Size, Knob::Format, Knob::Textures, Knob::DoubleBuffer, Knob::Depth};
  // What the example draws instead of a depth buffer ("triangles sorted far to near").
  std::string without_depth;
  // What it draws instead of each feature it uses (bilinear, blend, texturing, ...), for the
  // printed choice. A feature not listed here is one the example does not use.
  std::vector<std::pair<std::uint16_t, std::string>> without_feature;
};

struct Fit {
  DeviceCaps device;                  // what it was fitted to
  draw::ContextOptions context;       // size, format, depth buffer, double buffering
  std::uint16_t features = 0;         // what the example may use: the device's, less --without
  bool dither = false;                // TRI_MODE.DITHER on the example's draws
  std::vector<TextureFit> textures;   // in the order of Wants::textures (empty without texturing)
  std::uint64_t vram_bytes = 0;       // buffers and textures as the context places them
  std::vector<std::string> gave_up;   // what differs from the wants, and why

  bool has(std::uint16_t bit) const { return (features & bit) == bit; }
  bool painter() const { return !context.depth_buffer; }
  bool texturing() const { return has(kTexturing); }
  // The texture fitted for Wants::textures[i].
  const TextureFit& texture(std::size_t i) const { return textures.at(i); }
  // "320x240 RGBA2222 dithered, single buffer, painter's order; textures 64x64 RGB565; 81,920 of 131,072 bytes".
  std::string summary() const;
  // The same without the memory figures (equal on devices that differ only in memory size).
  std::string choice() const;
};

// The closest configuration to `wants` that fits `device`, honouring `request`. Errors: a forced
// size or format the device cannot take, or nothing fits (the message says what the smallest
// candidate needs).
Result<Fit> fit(const Wants& wants, const DeviceCaps& device, const FitRequest& request = {});

}  // namespace gpubridge::examples
