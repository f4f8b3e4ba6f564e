#pragma once
// The gateware's two profiles (gateware/rtl/spigpu_top.v) and what each reports in CAPS, so the
// simulator can be configured as the same device (docs/gateware.md, "Profiles").
#include <cstdint>
#include <optional>
#include <string_view>

namespace gpubridge::rtl {

enum class GatewareProfile : std::uint8_t { Up5k, Ecp5 };

std::string_view to_string(GatewareProfile p);
std::optional<GatewareProfile> parse_gateware_profile(std::string_view name);  // "up5k", "ecp5"

struct GatewareCaps {
  std::uint8_t features = 0;   // CAPS.FEATURES
  std::uint8_t features2 = 0;  // CAPS2.FEATURES2 (bit 0: depth buffer; the up5k has none)
  unsigned fifo_depth = 0;
  unsigned max_width = 0, max_height = 0;
  std::uint32_t vram_kib = 0;
  std::uint16_t variant = 0;  // ID.VARIANT
  double core_hz = 0;         // the clock the co-simulation model was built for
  std::uint64_t caps_register() const;
  std::uint64_t caps2_register() const;
  std::uint64_t id_register() const;
};

// Must match the localparams of gateware/rtl/spigpu_top.v (a test reads CAPS and ID through SPI).
GatewareCaps caps_of(GatewareProfile p);

}  // namespace gpubridge::rtl
