// `gpubridge boards` and `gpubridge cables`: the board profiles and bridge cables, from the data
// in configs/boards/*.json and configs/cables/*.json.
#include <algorithm>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::cli {
namespace {

std::string hex4(std::uint16_t v) {
  char b[8];
  std::snprintf(b, sizeof b, "%04x", v);
  return b;
}

// The programmers of a board in order of preference, each with the memories it can write.
std::vector<std::pair<std::string, std::vector<std::string>>> programmers(const std::string& fpga, const usb::FlashRecipe& recipe) {
  std::vector<std::pair<std::string, std::vector<std::string>>> out;
  const auto family = usb::fpga_family(fpga);
  if (!family) return out;
  for (const auto tool : {usb::FlashTool::OpenFpgaLoader, usb::FlashTool::Iceprog})
    for (const auto target : {usb::FlashTarget::Flash, usb::FlashTarget::Sram}) {
      const auto can = usb::flash_tools(*family, recipe, target);
      if (std::find(can.begin(), can.end(), tool) == can.end()) continue;
      if (out.empty() || out.back().first != usb::to_string(tool)) out.emplace_back(usb::to_string(tool), std::vector<std::string>{});
      out.back().second.emplace_back(usb::to_string(target));
    }
  return out;
}

nlohmann::json flash_json(const std::string& fpga, const usb::FlashRecipe& recipe) {
  if (!recipe.present) return nullptr;
  nlohmann::json by_tool = nlohmann::json::object();
  for (const auto& [tool, targets] : programmers(fpga, recipe)) by_tool[tool] = targets;
  nlohmann::json out{{"programmers", by_tool}};
  if (!recipe.bitstream.empty()) out["bitstream"] = recipe.bitstream;
  else out["source"] = recipe.source;
  return out;
}

// One line of the FLASH table: board, bitstream, "openfpgaloader (flash), iceprog (flash, sram)".
void print_flash_row(const std::string& name, const std::string& fpga, const usb::FlashRecipe& recipe) {
  if (!recipe.present) {
    std::printf("%-16s %-16s %s\n", name.c_str(), "-", "no flash recipe: use the board's own programmer");
    return;
  }
  std::string tools;
  for (const auto& [tool, targets] : programmers(fpga, recipe)) {
    std::string t;
    for (const auto& m : targets) t += (t.empty() ? "" : ", ") + m;
    tools += (tools.empty() ? "" : ", ") + tool + " (" + t + ")";
  }
  std::printf("%-16s %-16s %s\n", name.c_str(), recipe.bitstream.empty() ? "(yours)" : recipe.bitstream.c_str(), tools.c_str());
}

int run_boards(const GlobalOptions& g, const std::string& dir) {
  const auto config = dir.empty() ? usb::default_config_dir() : std::filesystem::path(dir);
  auto boards = usb::load_board_profiles(config);
  if (!boards) {
    std::fprintf(stderr, "gpubridge boards: %s\n", boards.error().message.c_str());
    return 1;
  }
  auto uart_boards = usb::load_uart_board_profiles(config);
  if (!uart_boards) {
    std::fprintf(stderr, "gpubridge boards: %s\n", uart_boards.error().message.c_str());
    return 1;
  }
  if (g.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& p : *boards)
      out.push_back({{"name", p.name},
                     {"device_kind", "spigpu"},
                     {"description", p.description},
                     {"fpga", p.fpga},
                     {"file", p.file.string()},
                     {"bridge",
                      {{"chip", usb::to_string(p.chip)},
                       {"vid", hex4(p.vid)},
                       {"pid", hex4(p.pid)},
                       {"interface", p.interface == 0 ? "A" : "B"},
                       {"spi_clock_hz", p.spi_clock_hz},
                       {"cs_pin", p.cs_pin},
                       {"busy_pin", p.busy_pin}}},
                     {"device",
                      {{"vram_kib", p.vram_kib}, {"max_width", p.max_width}, {"max_height", p.max_height}, {"fifo_depth", p.fifo_depth},
                       {"clock_mhz", p.clock_mhz}}},
                     {"strict_link", p.strict_link},
                     {"flash", flash_json(p.fpga, p.flash)}});
    for (const auto& p : *uart_boards)
      out.push_back({{"name", p.name},
                     {"device_kind", protocol::device_kind_info(p.device_kind).name},
                     {"description", p.description},
                     {"fpga", p.fpga},
                     {"file", p.file.string()},
                     {"uart",
                      {{"vid", hex4(p.vid)},
                       {"pid", hex4(p.pid)},
                       {"interface", std::string(1, static_cast<char>('A' + p.interface))},
                       {"baud", p.baud},
                       {"tty", p.tty}}},
                     {"flash", flash_json(p.fpga, p.flash)}});
    std::puts(json_text(out, 2).c_str());
    return 0;
  }
  std::printf("%-16s %-7s %-8s %-10s %8s %9s %9s  %s\n", "BOARD", "DEVICE", "BRIDGE", "VID:PID", "SPI MHz", "VRAM KiB", "MAX", "FPGA");
  for (const auto& p : *boards)
    std::printf("%-16s %-7s %-8s %s:%s %8.3g %9u %4ux%-4u  %s\n", p.name.c_str(), "spigpu", std::string(usb::to_string(p.chip)).c_str(),
                hex4(p.vid).c_str(), hex4(p.pid).c_str(), p.spi_clock_hz / 1e6, p.vram_kib, p.max_width, p.max_height, p.fpga.c_str());
  for (const auto& p : *uart_boards)
    std::printf("%-16s %-7s %-8s %s:%s %8s %9s %9s  %s (UART channel %c at %u baud; render --device %s --board %s)\n",
                p.name.c_str(), std::string(protocol::device_kind_info(p.device_kind).name).c_str(), "uart", hex4(p.vid).c_str(),
                hex4(p.pid).c_str(), "-", "-", "-", p.fpga.c_str(), static_cast<char>('A' + p.interface), p.baud,
                std::string(protocol::device_kind_info(p.device_kind).name).c_str(), p.name.c_str());
  // Which bitstream goes with which board, and what can program it (gpubridge flash --board NAME).
  std::printf("\n%-16s %-16s %s\n", "BOARD", "BITSTREAM", "PROGRAMMERS (gpubridge flash --board NAME [FILE])");
  for (const auto& p : *boards) print_flash_row(p.name, p.fpga, p.flash);
  for (const auto& p : *uart_boards) print_flash_row(p.name, p.fpga, p.flash);
  return 0;
}

int run_cables(const GlobalOptions& g, const std::string& dir) {
  auto cables = usb::load_cables(dir.empty() ? usb::default_config_dir() : std::filesystem::path(dir));
  if (!cables) {
    std::fprintf(stderr, "gpubridge cables: %s\n", cables.error().message.c_str());
    return 1;
  }
  if (g.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& c : *cables)
      out.push_back({{"name", c.name}, {"chip", c.chip}, {"vid", hex4(c.vid)}, {"pid", hex4(c.pid)}, {"api", c.api},
                     {"max_spi_hz", c.max_spi_hz}, {"interfaces", c.interfaces}, {"description", c.description}});
    std::puts(json_text(out, 2).c_str());
    return 0;
  }
  std::printf("%-10s %-10s %-7s %8s  %s\n", "CABLE", "VID:PID", "API", "MAX MHz", "DESCRIPTION");
  for (const auto& c : *cables)
    std::printf("%-10s %s:%s %-7s %8.3g  %s\n", c.name.c_str(), hex4(c.vid).c_str(), hex4(c.pid).c_str(), c.api.c_str(),
                c.max_spi_hz / 1e6, c.description.c_str());
  return 0;
}

}  // namespace

GPUBRIDGE_COMMAND("boards", 70, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  auto dir = std::make_shared<std::string>();
  auto* boards = app.add_subcommand("boards", "list the board profiles (configs/boards/*.json): device kind, bridge chip or UART, wiring, SPI clock, video memory");
  boards->add_option("--config-dir", *dir, "directory holding boards/ and cables/ (default: $GPUBRIDGE_CONFIG_DIR or the source tree's configs/)");
  runners.emplace_back(boards, [&g, dir] { return run_boards(g, *dir); });
  auto* cables = app.add_subcommand("cables", "list the USB-SPI bridge chips gpubridge can drive (configs/cables/*.json)");
  cables->add_option("--config-dir", *dir, "directory holding boards/ and cables/");
  runners.emplace_back(cables, [&g, dir] { return run_cables(g, *dir); });
});

}  // namespace gpubridge::cli
