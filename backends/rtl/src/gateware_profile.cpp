#include "gpubridge/rtl/gateware_profile.hpp"

#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::rtl {

std::string_view to_string(GatewareProfile p) { return p == GatewareProfile::Up5k ? "up5k" : "ecp5"; }

std::optional<GatewareProfile> parse_gateware_profile(std::string_view name) {
  if (name == "up5k") return GatewareProfile::Up5k;
  if (name == "ecp5") return GatewareProfile::Ecp5;
  return std::nullopt;
}

GatewareCaps caps_of(GatewareProfile p) {
  GatewareCaps c;
  if (p == GatewareProfile::Up5k) {
    c.features = 0x3C;  // dither, strict link, RGB565, RGBA2222 (no texturing, bilinear or blending)
    c.features2 = 0;    // no depth buffer (protocol 1.4): 458 packed cells and a SB_MAC16 the UP5K lacks room for
    c.fifo_depth = 64;
    c.max_width = 320;
    c.max_height = 240;
    c.vram_kib = 128;
    c.variant = 0x0001;
    c.core_hz = 25.125e6;  // the iCEBreaker top's PLL (12 MHz x 67 / 32), also its pixel clock
  } else {
    c.features = 0xFF;   // every feature of protocol 1.2
    c.features2 = 0x01;  // the depth buffer (CAPS2.FEATURES2 bit 0)
    c.fifo_depth = 1023;
    c.max_width = 1024;
    c.max_height = 768;
    c.vram_kib = 32768;
    c.variant = 0x0002;
    c.core_hz = 50e6;
  }
  return c;
}

std::uint64_t GatewareCaps::caps_register() const {
  return (std::uint64_t{features} << 56) | (std::uint64_t{fifo_depth} << 46) | (std::uint64_t{max_height} << 35) |
         (std::uint64_t{max_width} << 24) | vram_kib;
}

std::uint64_t GatewareCaps::caps2_register() const { return features2; }  // FEATURES2 in [7:0]

std::uint64_t GatewareCaps::id_register() const {
  return (std::uint64_t{protocol::kIdMagic} << 32) | (std::uint64_t{protocol::kVersionMajor} << 24) |
         (std::uint64_t{protocol::kVersionMinor} << 16) | variant;
}

}  // namespace gpubridge::rtl
