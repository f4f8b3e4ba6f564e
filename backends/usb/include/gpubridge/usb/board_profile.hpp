#pragma once
// Board profiles are data (configs/boards/*.json): which bridge chip, how it is wired, how fast
// the SPI link may run and what the FPGA design offers; each is checked against its chip's row in
// the chip table (bridge_chips.hpp). Cable descriptions (configs/cables/*.json) list the bridge
// chips `gpubridge probe` looks for, checked against the same table.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/device_kind.hpp"
#include "gpubridge/usb/bridge_chips.hpp"
#include "gpubridge/usb/flash_recipe.hpp"
#include "gpubridge/usb/ftdi_mpsse.hpp"

namespace gpubridge::usb {

enum class ScanoutMode : std::uint8_t { Readback, CrcOnly, Off };

struct BoardProfile {
  std::string name, description, fpga;
  std::filesystem::path file;
  // Bridge wiring.
  BridgeChip chip = BridgeChip::FT232H;
  std::uint16_t vid = 0, pid = 0;
  int interface = 0;          // FTDI channel A=0 / B=1; 0 for single-interface chips
  std::string serial;         // optional: select this adapter when several are attached
  std::string port_path;      // optional: select by USB port path
  std::uint32_t spi_clock_hz = 0;
  std::uint8_t cs_pin = 3;    // bridge GPIO used as chip select (FTDI ADBUS n, CH341A D0, MCP2210 GPn, CP2130 CSn)
  bool busy_pin = false;      // FPGA BUSY output wired to the bridge (FTDI GPIOL1)
  ReadEdge read_edge = ReadEdge::Rising;
  std::uint8_t latency_ms = 1;
  bool stream_reads = true;  // FTDI: reads beyond the RX FIFO through an asynchronous IN queue
  // FPGA design.
  std::uint32_t vram_kib = 0;
  unsigned max_width = 0, max_height = 0, fifo_depth = 0;
  double clock_mhz = 50;      // core clock of the design in MHz (25.125: the iCEBreaker's PLL), for the timing model (not sent anywhere)
  bool strict_link = true;
  ScanoutMode scanout = ScanoutMode::Readback;
  // The gateware this board runs (gateware/, docs/gateware.md): its profile ("up5k", "ecp5"; empty
  // when the profile names none) and the MISO timing the co-simulation (backend rtl:BOARD) applies:
  // the device's clock-to-pad plus wiring plus the bridge's input setup time.
  std::string gateware;
  unsigned miso_delay_ns = 20;
  FlashRecipe flash;          // how `gpubridge flash` programs the board (flash_recipe.hpp)
};

struct CableInfo {
  std::string name, chip, description, api;  // chip: a chip table name; api: that chip's ("libusb", "hidapi")
  std::uint16_t vid = 0, pid = 0;
  std::uint32_t max_spi_hz = 0;
  std::vector<std::string> interfaces;
  std::filesystem::path file;
};

// A board whose device is not spigpu and that is reached over a USB-UART rather than an SPI bridge:
// the iCEBreaker running tinygpus' standalone DMC-1 SOC (docs/dmc1.md, "Board path"). Same
// directory as the SPI boards; the file's "device_kind" says which loader reads it.
struct UartBoardProfile {
  std::string name, description, fpga;
  std::filesystem::path file;
  protocol::DeviceKind device_kind = protocol::DeviceKind::Dmc1;
  std::uint16_t vid = 0, pid = 0;  // the USB-UART
  int interface = 0;               // its USB interface (the iCEBreaker's FT2232H: channel B = 1)
  std::string serial;              // optional: select this adapter when several are attached
  std::string tty;                 // optional: a fixed port instead of finding it from the USB ids
  unsigned baud = 115200;
  FlashRecipe flash;
};

// GPUBRIDGE_CONFIG_DIR from the environment, else the source tree's configs/ (compile time).
std::filesystem::path default_config_dir();

// Errors name the file and the key ("configs/boards/x.json: bridge.spi_clock_hz: ...").
Result<BoardProfile> load_board_profile(const std::filesystem::path& file);
Result<BoardProfile> parse_board_profile(std::string_view json_text, const std::string& file_for_errors);
Result<std::vector<BoardProfile>> load_board_profiles(const std::filesystem::path& config_dir);
// Finds a profile by name in config_dir/boards, or loads `name_or_path` if it is a .json file.
Result<BoardProfile> find_board_profile(const std::filesystem::path& config_dir, const std::string& name_or_path);
// UART boards (files with a "device_kind" other than "spigpu"); the SPI loaders above skip them,
// and find_board_profile names the right command when asked for one.
Result<UartBoardProfile> parse_uart_board_profile(std::string_view json_text, const std::string& file_for_errors);
Result<std::vector<UartBoardProfile>> load_uart_board_profiles(const std::filesystem::path& config_dir);
Result<UartBoardProfile> find_uart_board_profile(const std::filesystem::path& config_dir, const std::string& name_or_path);
Result<std::vector<CableInfo>> load_cables(const std::filesystem::path& config_dir);

}  // namespace gpubridge::usb
