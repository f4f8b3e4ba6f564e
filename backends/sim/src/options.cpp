#include "gpubridge/sim/options.hpp"

#include <charconv>
#include <string>

namespace gpubridge::sim {
namespace {

struct KnobSpec {
  std::string_view name;
  unsigned min, max;
  unsigned AccuracyKnobs::*field;
};
constexpr KnobSpec kKnobs[] = {
    {"recip_bits", 1, 16, &AccuracyKnobs::recip_bits},
    {"nr_steps", 0, 4, &AccuracyKnobs::nr_steps},
    {"subpixel_bits", 0, 4, &AccuracyKnobs::subpixel_bits},
    {"z_bits", 1, 24, &AccuracyKnobs::z_bits},
};

std::string known_knobs() { return "recip_bits, nr_steps, subpixel_bits, z_bits; or the words preview, exact"; }

}  // namespace

Result<void> apply_knob(AccuracyKnobs& knobs, std::string_view setting) {
  if (setting == "preview") {
    knobs.preview = true;
    return {};
  }
  if (setting == "exact") {
    knobs = AccuracyKnobs{};
    return {};
  }
  if (setting.starts_with("fast=") || setting == "fast")
    return make_error("accuracy knob 'fast' was retired (it was slower than the exact path): use --accuracy preview for speed");
  const auto eq = setting.find('=');
  if (eq == std::string_view::npos || eq == 0)
    return make_error("accuracy setting '" + std::string(setting) + "' is not KNOB=VALUE (knobs: " + known_knobs() + ")");
  const std::string_view name = setting.substr(0, eq), text = setting.substr(eq + 1);
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  const bool numeric = ec == std::errc{} && end == text.data() + text.size() && !text.empty();
  for (const auto& k : kKnobs) {
    if (k.name != name) continue;
    if (!numeric || value < k.min || value > k.max)
      return make_error("accuracy knob " + std::string(name) + "=" + std::string(text) + ": expected an integer in " +
                        std::to_string(k.min) + ".." + std::to_string(k.max));
    knobs.*k.field = value;
    return {};
  }
  return make_error("unknown accuracy knob '" + std::string(name) + "' (knobs: " + known_knobs() + ")");
}

Result<AccuracyKnobs> parse_knobs(std::span<const std::string> settings) {
  AccuracyKnobs k;
  for (const auto& s : settings)
    if (auto r = apply_knob(k, s); !r) return r.error();
  return k;
}

std::string to_string(const AccuracyKnobs& k) {
  if (k.preview) {
    std::string s = "preview";
    if (k.subpixel_bits != 4) s += " subpixel_bits=" + std::to_string(k.subpixel_bits);
    if (k.z_bits != 24) s += " z_bits=" + std::to_string(k.z_bits);
    return s;
  }
  return "recip_bits=" + std::to_string(k.recip_bits) + " nr_steps=" + std::to_string(k.nr_steps) +
         " subpixel_bits=" + std::to_string(k.subpixel_bits) + " z_bits=" + std::to_string(k.z_bits);
}

std::string accuracy_mode(const AccuracyKnobs& k) { return k.preview ? "preview" : k.exact() ? "exact" : "knobs"; }

Result<void> DeviceOptions::validate() const {
  auto bad = [](std::string what) { return make_error("simulator option " + what); };
  if (vram_bytes < (64u << 10) || vram_bytes > kMaxVramBytes || vram_bytes % 1024 != 0)
    return bad("vram_bytes=" + std::to_string(vram_bytes) + ": expected a multiple of 1024 in 64 KiB .. 4 GiB");
  if (max_width < 1 || max_width > protocol::kMaxFramebufferDim)
    return bad("max_width=" + std::to_string(max_width) + ": expected 1..1024");
  if (max_height < 1 || max_height > protocol::kMaxFramebufferDim)
    return bad("max_height=" + std::to_string(max_height) + ": expected 1..1024");
  if (fifo_depth < 64 || fifo_depth > 1023)
    return bad("fifo_depth=" + std::to_string(fifo_depth) + ": expected 64..1023 (CAPS.FIFO_DEPTH is 10 bits)");
  if (features2 & ~kAllFeatures2)
    return bad("features2=" + std::to_string(features2) + ": expected only bit 0 (CAPS2.FEATURES2 bits 1..7 are reserved)");
  if (fifo_drain_interval < 1 || fifo_drain_interval > 1024)
    return bad("fifo_drain_interval=" + std::to_string(fifo_drain_interval) + ": expected 1..1024");
  if (threads < 1 || threads > kMaxThreads)
    return bad("threads=" + std::to_string(threads) + ": expected 1.." + std::to_string(kMaxThreads));
  const AccuracyKnobs& k = accuracy;
  if (k.recip_bits < 1 || k.recip_bits > 16 || k.nr_steps > 4 || k.subpixel_bits > 4 || k.z_bits < 1 || k.z_bits > 24)
    return bad("accuracy knobs out of range: " + to_string(k));
  if (k.preview && (k.recip_bits != 10 || k.nr_steps != 1))
    return bad("accuracy preview has no reciprocal table: recip_bits and nr_steps do not apply (preview takes subpixel_bits and z_bits)");
  return {};
}

}  // namespace gpubridge::sim
