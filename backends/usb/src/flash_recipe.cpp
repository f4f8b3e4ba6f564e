#include "gpubridge/usb/flash_recipe.hpp"

#include <algorithm>
#include <array>
#include <cctype>

#include <fmt/format.h>

#include "gpubridge/backends/backend.hpp"

namespace gpubridge::usb {
namespace {

Error bad(std::string message) { return make_error(std::move(message), backends::kBadRequest); }

std::string hex32(std::uint32_t v) { return fmt::format("{:#010x}", v); }
std::string hex4(std::uint16_t v) { return fmt::format("{:#06x}", v); }

// ECP5 parts by JTAG IDCODE (Lattice's BSDL files; ecppack --idcode takes the same numbers).
struct Ecp5Part {
  std::string_view name;
  std::uint32_t idcode;
};
constexpr std::array<Ecp5Part, 4> kEcp5Parts{{
    {"LFE5U-12F", 0x21111043},
    {"LFE5U-25F", 0x41111043},
    {"LFE5U-45F", 0x41112043},
    {"LFE5U-85F", 0x41113043},
}};

// Where `pattern` starts in the first `window` bytes of `bytes`.
std::optional<std::size_t> find_in_head(std::span<const std::uint8_t> bytes, std::span<const std::uint8_t> pattern, std::size_t window) {
  const auto head = bytes.first(std::min(bytes.size(), window));
  const auto it = std::search(head.begin(), head.end(), pattern.begin(), pattern.end());
  if (it == head.end()) return std::nullopt;
  return static_cast<std::size_t>(it - head.begin());
}

// The sync words come after a comment block (FF 00 ... 00 FF) of a few hundred bytes at most.
constexpr std::size_t kHeaderWindow = 4096;
constexpr std::array<std::uint8_t, 4> kIce40Sync{0x7E, 0xAA, 0x99, 0x7E};
constexpr std::array<std::uint8_t, 4> kEcp5Preamble{0xFF, 0xFF, 0xBD, 0xB3};
constexpr std::uint8_t kEcp5VerifyId = 0xE2;  // VERIFY_ID: 24 bits of zero, then the 32-bit IDCODE

}  // namespace

std::string_view to_string(FlashTool tool) { return tool == FlashTool::Iceprog ? "iceprog" : "openfpgaloader"; }
std::string_view executable_of(FlashTool tool) { return tool == FlashTool::Iceprog ? "iceprog" : "openFPGALoader"; }
std::string_view to_string(FlashTarget target) { return target == FlashTarget::Sram ? "sram" : "flash"; }

std::optional<FlashTool> parse_flash_tool(std::string_view name) {
  if (name == "openfpgaloader" || name == "openFPGALoader") return FlashTool::OpenFpgaLoader;
  if (name == "iceprog") return FlashTool::Iceprog;
  return std::nullopt;
}

std::optional<FpgaFamily> fpga_family(std::string_view fpga) {
  if (fpga.starts_with("iCE40")) return FpgaFamily::Ice40;
  if (fpga.starts_with("ECP5")) return FpgaFamily::Ecp5;
  return std::nullopt;
}

std::optional<std::uint32_t> ecp5_idcode(std::string_view fpga) {
  for (const auto& part : kEcp5Parts) {
    const auto at = fpga.find(part.name);
    // The part name ends there ("LFE5U-25F", not the start of a longer name).
    const auto end = at + part.name.size();
    if (at != std::string_view::npos && (end == fpga.size() || !std::isalnum(static_cast<unsigned char>(fpga[end])))) return part.idcode;
  }
  return std::nullopt;
}

std::vector<FlashTool> flash_tools(FpgaFamily family, const FlashRecipe& recipe, FlashTarget target) {
  std::vector<FlashTool> tools;
  // openFPGALoader writes an iCE40 board's SPI flash directly (it has no iCE40 SRAM mode); an ECP5
  // it loads over JTAG into SRAM (-m) or, through the FPGA, into the flash (-f).
  if (!recipe.openfpgaloader_board.empty() && (family == FpgaFamily::Ecp5 || target == FlashTarget::Flash))
    tools.push_back(FlashTool::OpenFpgaLoader);
  // iceprog: the flash by default, SRAM with -S (boards wired like the iCEBreaker).
  if (recipe.iceprog && family == FpgaFamily::Ice40) tools.push_back(FlashTool::Iceprog);
  return tools;
}

Result<FlashPlan> plan_flash(const FlashRequest& rq, const std::function<bool(std::string_view exe)>& installed) {
  if (!rq.recipe.present)
    return bad("board \"" + rq.board + "\" has no \"flash\" section in its profile: gpubridge does not know how to program it; "
               "use your board's own programmer (docs/boards.md)");
  const auto candidates = flash_tools(rq.family, rq.recipe, rq.target);
  std::string offered;
  for (const auto t : flash_tools(rq.family, rq.recipe, rq.target == FlashTarget::Flash ? FlashTarget::Sram : FlashTarget::Flash))
    offered += std::string(offered.empty() ? "" : ", ") + std::string(to_string(t));
  if (candidates.empty())
    return bad("board \"" + rq.board + "\": no programmer in its profile can write its " + std::string(to_string(rq.target)) +
               (offered.empty() ? std::string() : " (for the other memory: " + offered + "; try --to " +
                                                       std::string(to_string(rq.target == FlashTarget::Flash ? FlashTarget::Sram : FlashTarget::Flash)) + ")"));
  FlashPlan plan;
  plan.target = rq.target;
  if (rq.tool) {
    if (std::find(candidates.begin(), candidates.end(), *rq.tool) == candidates.end()) {
      std::string names;
      for (const auto t : candidates) names += std::string(names.empty() ? "" : ", ") + std::string(to_string(t));
      return bad("board \"" + rq.board + "\": " + std::string(to_string(*rq.tool)) + " cannot write its " +
                 std::string(to_string(rq.target)) + " (can: " + names + ")");
    }
    plan.tool = *rq.tool;
  } else {
    plan.tool = candidates.front();
    for (const auto t : candidates)
      if (installed(executable_of(t))) {
        plan.tool = t;
        break;
      }
  }
  plan.installed = installed(executable_of(plan.tool));

  auto& a = plan.argv;
  a.emplace_back(executable_of(plan.tool));
  if (plan.tool == FlashTool::OpenFpgaLoader) {
    a.insert(a.end(), {"-b", rq.recipe.openfpgaloader_board});
    if (rq.family == FpgaFamily::Ecp5) a.emplace_back(rq.target == FlashTarget::Flash ? "-f" : "-m");
    if (!rq.serial.empty()) a.insert(a.end(), {"--ftdi-serial", rq.serial});
  } else {
    const auto& serial = rq.serial.empty() ? rq.board_serial : rq.serial;
    a.emplace_back("-d");
    a.emplace_back(serial.empty() ? "i:" + hex4(rq.vid) + ":" + hex4(rq.pid) : "s:" + hex4(rq.vid) + ":" + hex4(rq.pid) + ":" + serial);
    a.insert(a.end(), {"-I", std::string(1, static_cast<char>('A' + rq.interface))});
    if (rq.target == FlashTarget::Sram) a.emplace_back("-S");
  }
  a.push_back(rq.bitstream.string());
  return plan;
}

Result<void> check_bitstream(std::span<const std::uint8_t> bytes, FpgaFamily family, std::optional<std::uint32_t> idcode,
                             const std::string& file) {
  if (bytes.empty()) return bad(file + ": empty file, not a bitstream");
  if (family == FpgaFamily::Ice40) {
    if (!find_in_head(bytes, kIce40Sync, kHeaderWindow))
      return bad(file + ": not an iCE40 bitstream (no 7E AA 99 7E sync word in its first 4 KiB): pass the .bin that icepack "
                        "writes, not the .asc or the synthesis .json");
    return {};
  }
  const auto at = find_in_head(bytes, kEcp5Preamble, kHeaderWindow);
  if (!at)
    return bad(file + ": not an ECP5 bitstream (no FF FF BD B3 preamble in its first 4 KiB): pass the .bit that ecppack "
                      "writes, not the .config or the synthesis .json");
  if (!idcode) return {};
  // VERIFY_ID follows the preamble within a few commands (dummy bytes, LSC_RESET_CRC).
  const auto tail = bytes.subspan(*at + kEcp5Preamble.size());
  for (std::size_t i = 0; i + 8 <= tail.size() && i < 64; ++i) {
    if (tail[i] != kEcp5VerifyId || tail[i + 1] != 0 || tail[i + 2] != 0 || tail[i + 3] != 0) continue;
    const std::uint32_t packed = (std::uint32_t{tail[i + 4]} << 24) | (std::uint32_t{tail[i + 5]} << 16) |
                                 (std::uint32_t{tail[i + 6]} << 8) | tail[i + 7];
    if (packed == *idcode) return {};
    std::string part = "an unknown part";
    for (const auto& p : kEcp5Parts)
      if (p.idcode == packed) part = "an " + std::string(p.name);
    return bad(file + ": packed for IDCODE " + hex32(packed) + " (" + part + "), but this board's FPGA has IDCODE " + hex32(*idcode) +
               ": the FPGA would refuse it; rebuild for the board's part (nextpnr-ecp5 --85k, ecppack --idcode) or pick the right --board");
  }
  return {};  // no VERIFY_ID (ecppack without an IDCODE check): nothing more to compare
}

}  // namespace gpubridge::usb
