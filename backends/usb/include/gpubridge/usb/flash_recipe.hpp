#pragma once
// How a board is programmed: the "flash" section of configs/boards/*.json says which bitstream file
// the project's gateware build writes for the board and which programmers (openFPGALoader, iceprog,
// both Debian packages) can load it. plan_flash turns that and the user's choices into the
// programmer's argv, and check_bitstream looks at a file's bytes before anything is written to a
// board; neither does I/O (the `gpubridge flash` command reads the file and runs the programmer).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gpubridge/common/result.hpp"

namespace gpubridge::usb {

enum class FpgaFamily : std::uint8_t { Ice40, Ecp5 };
enum class FlashTool : std::uint8_t { OpenFpgaLoader, Iceprog };
// Flash: the configuration flash, kept across power cycles. Sram: the FPGA's configuration memory,
// lost at power-off (a quick load for bring-up).
enum class FlashTarget : std::uint8_t { Flash, Sram };

std::string_view to_string(FlashTool tool);        // "openfpgaloader", "iceprog"
std::string_view executable_of(FlashTool tool);    // "openFPGALoader", "iceprog"
std::string_view to_string(FlashTarget target);    // "flash", "sram"
std::optional<FlashTool> parse_flash_tool(std::string_view name);

// The family of a board profile's "fpga" text ("iCE40 UP5K", "ECP5 LFE5U-85F"), if it names one.
std::optional<FpgaFamily> fpga_family(std::string_view fpga);
// The JTAG IDCODE an ECP5 bitstream for that part carries (ecppack writes it into VERIFY_ID), if known.
std::optional<std::uint32_t> ecp5_idcode(std::string_view fpga);

struct FlashRecipe {
  bool present = false;               // the profile has a "flash" section
  std::string bitstream;              // file name the gateware build writes; empty: not built by this project
  std::string openfpgaloader_board;   // openFPGALoader -b NAME; empty: openFPGALoader not offered
  bool iceprog = false;               // iceprog can program the board (iCE40, FTDI on the profile's USB ids)
  std::string source;                 // where a bitstream that is not built here comes from (shown in errors)
};

// The tools that can write `target` on a board of `family` with `recipe`, in order of preference.
std::vector<FlashTool> flash_tools(FpgaFamily family, const FlashRecipe& recipe, FlashTarget target);

struct FlashRequest {
  std::string board;                  // for messages
  FpgaFamily family = FpgaFamily::Ice40;
  FlashRecipe recipe;
  std::uint16_t vid = 0, pid = 0;     // the board's FTDI (iceprog -d)
  int interface = 0;                  // its channel (iceprog -I)
  std::string serial;                 // the user's choice of programmer among several (empty: the first)
  std::string board_serial;           // the profile's FTDI serial: iceprog's default (openFPGALoader's
                                      // board may be programmed through another chip, the ULX3S's FT231X)
  std::optional<FlashTool> tool;      // empty: the first of flash_tools() that `installed` accepts
  FlashTarget target = FlashTarget::Flash;
  std::filesystem::path bitstream;
};

struct FlashPlan {
  FlashTool tool = FlashTool::OpenFpgaLoader;
  FlashTarget target = FlashTarget::Flash;
  bool installed = false;             // the tool's executable was found
  std::vector<std::string> argv;      // argv[0] is the executable name, looked up on PATH
};

// `installed` says whether an executable is on PATH. Without an explicit tool, an installed one is
// preferred; if none is, the plan names the first candidate with installed = false so the caller
// can say what to install.
Result<FlashPlan> plan_flash(const FlashRequest& request, const std::function<bool(std::string_view exe)>& installed);

// Checks that `bytes` look like a bitstream for `family` (the sync word of the file icepack or
// ecppack writes) and, for ECP5, that the IDCODE it was packed for is `idcode` when both are known.
Result<void> check_bitstream(std::span<const std::uint8_t> bytes, FpgaFamily family, std::optional<std::uint32_t> idcode,
                             const std::string& file_for_errors);

}  // namespace gpubridge::usb
