#pragma once
// The USB-SPI bridge chips gpubridge drives, one row each (bridge_chips.cpp): the one place to add
// a chip. A row names the chip as the configs do (boards' "bridge.chip", cables' "chip"), gives
// its factory USB ids, how the host reaches it, its clock limit and wiring options, how to open
// its driver on a transport and how to build its byte-exact model for emulation. Board profiles
// are checked against the row of their chip, and configs/cables/*.json against the table.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "gpubridge/common/result.hpp"

namespace gpubridge::usb {

enum class BridgeChip : std::uint8_t { FT232H, FT2232H, FT4232H, CH341A, MCP2210, CP2130 };

// How the host reaches the chip (cables' "api").
enum class UsbApi : std::uint8_t { Libusb, Hidapi };
std::string_view to_string(UsbApi api);  // "libusb" | "hidapi"

struct BoardProfile;
class SpiBridge;
class UsbDevice;
class HidDevice;
namespace emu {
class ChipModel;
class SpiPins;
struct EmulationOptions;
}  // namespace emu

// The device a driver talks to, real or modelled: `usb` for libusb chips, `hid` for hidapi chips.
struct BridgeTransport {
  UsbDevice* usb = nullptr;
  HidDevice* hid = nullptr;
};

struct BridgeChipInfo {
  BridgeChip chip;
  std::string_view name;   // "ft232h": the spelling in configs and on the command line
  std::string_view label;  // "FT232H": the spelling in messages
  std::uint16_t vid, pid;  // factory USB ids
  UsbApi api;
  std::uint32_t max_clock_hz;  // fastest SCK the driver can set
  unsigned channels;           // SPI-capable interfaces: FTDI MPSSE channels A (and B); 1 for the others
  std::uint8_t cs_min, cs_max; // bridge.cs_pin values a profile may give (drivers check more at open)
  std::string_view cs_rule;    // the message when cs_pin is outside cs_min..cs_max or is busy_gpio
  int busy_gpio;               // the pin that waits on the FPGA's BUSY in hardware (FTDI GPIOL1), -1 = none
  bool stream_reads;           // the driver can stream reads beyond the RX FIFO (profile key bridge.stream_reads)
  // Opens the chip's driver on a transport (a real libusb/hidapi device or this chip's model).
  Result<std::unique_ptr<SpiBridge>> (*open_driver)(const BoardProfile& profile, BridgeTransport transport);
  // Builds the chip's model for an emulated board, driving `pins` (nullptr: nothing attached).
  std::unique_ptr<emu::ChipModel> (*make_model)(const BoardProfile& profile, const emu::EmulationOptions& opts,
                                                emu::SpiPins* pins);
};

// Every chip, in BridgeChip order.
std::span<const BridgeChipInfo> bridge_chips();
const BridgeChipInfo& chip_info(BridgeChip chip);
const BridgeChipInfo* find_chip(std::string_view name);  // by `name`; nullptr when unknown
std::string_view to_string(BridgeChip chip);             // chip_info(chip).name
std::optional<BridgeChip> parse_bridge_chip(std::string_view name);
std::string chip_names(std::string_view separator = ", ");  // "ft232h, ft2232h, ..." for messages

// Opens the profile's driver on a transport: the real USB/HID device or the chip's model.
Result<std::unique_ptr<SpiBridge>> open_bridge(const BoardProfile& profile, BridgeTransport transport);

}  // namespace gpubridge::usb
