#pragma once
// An emulated board: device model (the simulator, or the reference target) → SPI slave →
// byte-exact bridge chip model (built by the chip table) → the real driver → BoardBackend.
// Everything below the driver is a model; the driver code is the same one that talks to
// libusb/hidapi. The SPI pins are the seam (spi_pins.hpp): EmulationOptions::pins puts something
// else behind the chip model (the rtl backend's Verilated gateware).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gpubridge/usb/board_backend.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/bridge_chips.hpp"
#include "gpubridge/usb/emu/fault_plan.hpp"
#include "gpubridge/usb/emu/spi_pins.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"
#include "gpubridge/usb/hid_device.hpp"
#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb::emu {

class ChipModel;
class Mcp2210Model;

// Builds what sits behind the FPGA's SPI pins, for a board profile.
using PinsFactory = std::function<Result<std::unique_ptr<SpiPins>>(const BoardProfile& profile)>;

struct EmulationOptions {
  bool use_simulator = true;     // drive the simulator's device model (false: the reference target)
  unsigned drain_per_frame = 0;  // device slower than the link (flow-control tests); 0 = instant
  bool high_speed = true;        // FTDI: 512-byte packets (false: 64, behind a full-speed hub)
  std::string serial = "EMU00001";
  // Emulated hot-plug: the board is plugged in only while this file exists (empty = always). An
  // absent file makes enumeration fail and every transfer return NO_DEVICE, as libusb would.
  std::string presence_file;
  // Replaces the C++ SPI slave and device model behind the chip model (empty: SpiSlave driving
  // the simulator or the reference target). Power cycles are then the pins' own business.
  PinsFactory pins;
};

class EmulatedStack {
 public:
  static Result<std::unique_ptr<EmulatedStack>> create(const BoardProfile& profile, EmulationOptions opts = {});
  ~EmulatedStack();

  // The transport the driver uses: exactly one of these is non-null (HID for MCP2210).
  UsbDevice* usb();
  HidDevice* hid();
  BridgeTransport transport();
  ChipModel& chip();
  Mcp2210Model* mcp2210();  // for busy/external-master injection (nullptr for other chips)
  FaultPlan& usb_faults();
  // Every request the chip model refused or flagged (a correct driver produces none).
  std::vector<std::string> violations() const;
  SpiPins& pins();
  // The C++ SPI slave and its device model; std::logic_error when EmulationOptions::pins replaced them.
  SpiFaults& spi_faults();
  SpiSlave& slave();
  backends::SpiTarget& target();
  bool target_is_simulator() const;  // false as well when the pins were replaced
  void power_cycle();

  struct Impl;

 private:
  explicit EmulatedStack(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

struct EmulatedBoard {
  std::shared_ptr<EmulatedStack> stack;  // also owned by the backend; kept here for fault injection
  std::unique_ptr<BoardBackend> backend;
};
Result<EmulatedBoard> open_emulated_board(const BoardProfile& profile, EmulationOptions opts = {}, BoardOptions board = {});

}  // namespace gpubridge::usb::emu
