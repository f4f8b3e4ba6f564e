#pragma once
// Opens the board a profile describes: through libusb/hidapi, or fully emulated (chip model +
// simulator) so the same driver code runs without hardware.
#include <memory>
#include <string>

#include "gpubridge/usb/board_backend.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"

namespace gpubridge::usb {

struct BoardOpenOptions {
  bool emulate = false;
  std::uint32_t emulated_max_reliable_hz = 0;  // emulation only: MISO errors above this SCK (0 = none)
  std::string emulated_presence_file;          // emulation only: plugged in while this file exists ("" = always)
  emu::PinsFactory emulated_pins;              // emulation only: what drives the SPI pins (empty = SpiSlave + simulator)
  BoardOptions board;
};

Result<std::unique_ptr<BoardBackend>> open_board(const BoardProfile& profile, const BoardOpenOptions& opts = {});

}  // namespace gpubridge::usb
