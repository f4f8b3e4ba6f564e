#pragma once
// Board profiles used by the tests: built in code so each test states the wiring it relies on. The
// chip's USB ids, fastest SCK and first legal chip-select pin come from its row of the chip table.
#include <string>

#include "gpubridge/usb/board_profile.hpp"

namespace gpubridge::usb::test {

inline BoardProfile profile_for(BridgeChip chip, bool busy_pin = false) {
  const BridgeChipInfo& info = chip_info(chip);
  BoardProfile p;
  p.name = "test-" + std::string(info.name);
  p.chip = chip;
  p.vid = info.vid;
  p.pid = info.pid;
  p.spi_clock_hz = info.max_clock_hz;
  p.cs_pin = info.cs_min;
  p.busy_pin = busy_pin;
  p.vram_kib = 256;
  p.max_width = 64;
  p.max_height = 64;
  p.fifo_depth = 128;
  p.strict_link = true;
  return p;
}

}  // namespace gpubridge::usb::test
