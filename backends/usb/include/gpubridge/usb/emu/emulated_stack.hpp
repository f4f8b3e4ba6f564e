#pragma once
// An emulated board: device model (the simulator when built, else the reference target) → SPI
// slave → byte-exact bridge chip model → the real driver → BoardBackend. Everything below the
// driver is a model; the driver code is the same one that talks to libusb/hidapi.
#include <memory>
#include <string>
#include <vector>

#include "gpubridge/usb/board_backend.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/emu/fault_plan.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"
#include "gpubridge/usb/hid_device.hpp"
#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb::emu {

class Mcp2210Model;

struct EmulationOptions {
  bool use_simulator = true;     // drive the simulator's device model when it is built
  unsigned drain_per_frame = 0;  // device slower than the link (flow-control tests); 0 = instant
  bool high_speed = true;        // FTDI: 512-byte packets (false: 64, behind a full-speed hub)
  std::string serial = "EMU00001";
  // Emulated hot-plug: the board is plugged in only while this file exists (empty = always). An
  // absent file makes enumeration fail and every transfer return NO_DEVICE, as libusb would.
  std::string presence_file;
};

class EmulatedStack {
 public:
  static Result<std::unique_ptr<EmulatedStack>> create(const BoardProfile& profile, EmulationOptions opts = {});
  ~EmulatedStack();

  // The transport the driver uses: exactly one of these is non-null (HID for MCP2210).
  UsbDevice* usb();
  HidDevice* hid();
  Mcp2210Model* mcp2210();  // for busy/external-master injection (nullptr for other chips)
  FaultPlan& usb_faults();
  SpiFaults& spi_faults();
  SpiSlave& slave();
  backends::SpiTarget& target();
  bool target_is_simulator() const;
  // Every request the chip model refused or flagged (a correct driver produces none).
  std::vector<std::string> violations() const;
  void power_cycle();

  struct Impl;

 private:
  explicit EmulatedStack(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Opens the driver for the profile's chip on a transport (model or real).
Result<std::unique_ptr<SpiBridge>> open_bridge(const BoardProfile& profile, UsbDevice* usb, HidDevice* hid);

struct EmulatedBoard {
  std::shared_ptr<EmulatedStack> stack;  // also owned by the backend; kept here for fault injection
  std::unique_ptr<BoardBackend> backend;
};
Result<EmulatedBoard> open_emulated_board(const BoardProfile& profile, EmulationOptions opts = {}, BoardOptions board = {});

}  // namespace gpubridge::usb::emu
