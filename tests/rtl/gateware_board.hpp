#pragma once
// A gateware board on the test bench: the full bridge path (driver -> libusb/hidapi-shaped
// transport -> byte-exact chip model -> SPI pins -> Verilated gateware) and, on the same wires, the
// simulator behind the C++ SPI-slave model configured with the gateware's CAPS. Both devices see
// every CS edge and MOSI bit (bit errors included); afterwards their video memory, scanned-out frames,
// error flags and every timing-independent register read must agree.
#include <memory>
#include <string>
#include <vector>

#include "gpubridge/rtl/rtl_device.hpp"
#include "gpubridge/sim/device.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "gpubridge/usb/emu/rtl_pins.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"

namespace gpubridge::test {

// The board profile a test uses: a profile from configs/boards, or a generic one given a gateware.
usb::BoardProfile board_profile(const std::string& name);
usb::BoardProfile with_gateware(usb::BoardProfile p, const std::string& gateware, std::uint32_t spi_clock_hz);

class GatewareBoard {
 public:
  static Result<std::unique_ptr<GatewareBoard>> open(const usb::BoardProfile& profile, usb::BoardOptions opts = {});

  backends::Backend& backend() { return *board_.backend; }
  usb::BoardBackend& board() { return *board_.backend; }
  usb::emu::EmulatedStack& stack() { return *board_.stack; }
  usb::emu::RtlPins& pins() { return *usb::emu::rtl_pins_of(stack()); }
  rtl::RtlDevice& gateware() { return pins().device(); }
  sim::Device& sim() { return *sim_; }

  // Empty when equal: video memory byte for byte, every frame the gateware scanned out against the
  // simulator's frame of the same swap, the frames the board backend reported (CRC, and pixels when
  // it read them back), the register reads compared on the wires, and STATUS.ERRORS (read through the
  // board, compared with the simulator's flags).
  std::string compare(bool errors_too = true);
  // Only the first `bytes` of video memory take part in compare() (what a test uses; 0 = all).
  void limit_compare(std::uint64_t bytes) { compare_limit_ = bytes; }
  const std::vector<rtl::ScanFrame>& gateware_frames() const { return gw_frames_; }
  std::size_t reads_compared() const { return reads_compared_; }
  // While on, every read frame on the wires of a register whose value does not depend on timing
  // (not STATUS, FRAME_CRC, MEM_ADDR, MEM_DATA) must return the same value from both devices; use it
  // when the devices are idle.
  void compare_reads(bool on) { compare_all_reads_ = on; }

 private:
  GatewareBoard() = default;
  usb::emu::EmulatedBoard board_;
  std::unique_ptr<sim::Device> sim_;
  std::unique_ptr<usb::emu::SpiSlave> sim_pins_;
  std::vector<rtl::ScanFrame> gw_frames_;
  std::vector<backends::ScanoutFrame> sim_frames_;
  std::vector<std::shared_ptr<const backends::ScanoutFrame>> board_frames_;
  std::vector<std::string> read_mismatches_;
  std::size_t reads_compared_ = 0;
  std::uint64_t compare_limit_ = 0;
  bool compare_all_reads_ = false;
  std::unique_ptr<backends::SpiTarget> trace_;
};

}  // namespace gpubridge::test
