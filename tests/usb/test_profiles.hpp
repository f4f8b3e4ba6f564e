#pragma once
// Board profiles used by the tests: built in code so each test states the wiring it relies on.
#include <string>

#include "gpubridge/usb/board_profile.hpp"

namespace gpubridge::usb::test {

inline BoardProfile profile_for(BridgeChip chip, bool busy_pin = false) {
  BoardProfile p;
  p.name = "test-" + std::string(to_string(chip));
  p.chip = chip;
  p.spi_clock_hz = 30'000'000;
  p.cs_pin = 3;
  switch (chip) {
    case BridgeChip::FT232H: p.vid = 0x0403; p.pid = 0x6014; break;
    case BridgeChip::FT2232H: p.vid = 0x0403; p.pid = 0x6010; break;
    case BridgeChip::FT4232H: p.vid = 0x0403; p.pid = 0x6011; break;
    case BridgeChip::CH341A: p.vid = 0x1a86; p.pid = 0x5512; p.spi_clock_hz = 1'700'000; p.cs_pin = 0; break;
    case BridgeChip::MCP2210: p.vid = 0x04d8; p.pid = 0x00de; p.spi_clock_hz = 12'000'000; p.cs_pin = 0; break;
    case BridgeChip::CP2130: p.vid = 0x10c4; p.pid = 0x87a0; p.spi_clock_hz = 12'000'000; p.cs_pin = 0; break;
  }
  p.busy_pin = busy_pin;
  p.vram_kib = 256;
  p.max_width = 64;
  p.max_height = 64;
  p.fifo_depth = 128;
  p.strict_link = true;
  return p;
}

}  // namespace gpubridge::usb::test
