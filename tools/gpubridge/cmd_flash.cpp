// `gpubridge flash --board NAME [BITSTREAM]`: programs a board through openFPGALoader or iceprog
// (Debian packages), as the board profile's "flash" section says (usb/flash_recipe.hpp). The
// bitstream is checked before anything touches the board; the programmer's own output goes to
// stderr so that --json leaves stdout to the report.
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gpubridge/common/json_text.hpp"
#include "gpubridge/usb/board_profile.hpp"

extern char** environ;

namespace gpubridge::cli {
namespace {

// Bitstreams are a few MiB at most (an LFE5U-85F's is about 2.3 MB uncompressed).
constexpr std::uintmax_t kMaxBitstreamBytes = 16u << 20;

struct FlashArgs {
  std::string board, bitstream, config_dir, tool, serial, target = "flash";
  bool dry_run = false;
};

std::filesystem::path bitstream_dir() {
  if (const char* env = std::getenv("GPUBRIDGE_BITSTREAM_DIR"); env && *env) return env;
  return GPUBRIDGE_DEFAULT_BITSTREAM_DIR;
}

bool on_path(std::string_view exe) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::string_view rest = path;
  while (true) {
    const auto colon = rest.find(':');
    const auto dir = rest.substr(0, colon);
    const auto candidate = std::filesystem::path(dir.empty() ? "." : std::string(dir)) / std::string(exe);
    if (::access(candidate.c_str(), X_OK) == 0) return true;
    if (colon == std::string_view::npos) return false;
    rest.remove_prefix(colon + 1);
  }
}

// What a board profile contributes to a flash request, whichever loader reads it.
struct BoardForFlash {
  std::string name, fpga;
  std::filesystem::path file;
  usb::FlashRecipe recipe;
  std::uint16_t vid = 0, pid = 0;
  std::string serial;
};

BoardForFlash for_flash(const usb::BoardProfile& p) { return {p.name, p.fpga, p.file, p.flash, p.vid, p.pid, p.serial}; }
BoardForFlash for_flash(const usb::UartBoardProfile& p) { return {p.name, p.fpga, p.file, p.flash, p.vid, p.pid, p.serial}; }

// A board by name, or a profile file (.json) of either kind, as probe and bringup take it.
Result<BoardForFlash> find_board(const std::filesystem::path& config, const std::string& name) {
  if (name.size() > 5 && name.ends_with(".json")) {
    auto spi = usb::load_board_profile(name);
    if (spi) return for_flash(*spi);
    if (auto uart = usb::find_uart_board_profile(config, name)) return for_flash(*uart);
    return spi.error();
  }
  auto spi = usb::load_board_profiles(config);
  if (!spi) return spi.error();
  auto uart = usb::load_uart_board_profiles(config);
  if (!uart) return uart.error();
  std::string names;
  for (const auto& p : *spi) {
    if (p.name == name) return for_flash(p);
    names += (names.empty() ? "" : ", ") + p.name;
  }
  for (const auto& p : *uart) {
    if (p.name == name) return for_flash(p);
    names += ", " + p.name;
  }
  return make_error("no board profile named \"" + name + "\" in " + (config / "boards").string() + " (known: " + names +
                    "; `gpubridge boards` lists them)");
}

Result<std::vector<std::uint8_t>> read_bitstream(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    return make_error(file.string() + ": no such file" + (ec ? " (" + ec.message() + ")" : std::string()));
  const auto size = std::filesystem::file_size(file, ec);
  if (ec) return make_error(file.string() + ": cannot read: " + ec.message());
  if (size > kMaxBitstreamBytes) return make_error(file.string() + ": " + std::to_string(size) + " bytes, larger than any bitstream of these FPGAs (16 MiB)");
  std::ifstream in(file, std::ios::binary);
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.eof() && in.fail()) return make_error(file.string() + ": cannot read: " + std::strerror(errno));
  return bytes;
}

// Runs argv (looked up on PATH) with its stdout sent to our stderr; its exit code, or -signal.
Result<int> run_programmer(const std::vector<std::string>& argv) {
  std::vector<char*> cargv;
  for (const auto& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
  cargv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, STDERR_FILENO, STDOUT_FILENO);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, cargv[0], &actions, nullptr, cargv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return make_error("cannot start " + argv[0] + ": " + std::strerror(rc));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return make_error("waiting for " + argv[0] + ": " + std::strerror(errno));
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return -WTERMSIG(status);
}

std::string command_line(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) {
    const bool plain = !a.empty() && a.find_first_of(" \t'\"\\$`") == std::string::npos;
    s += (s.empty() ? "" : " ") + (plain ? a : "'" + a + "'");
  }
  return s;
}

int fail(const std::string& what) {
  std::fprintf(stderr, "gpubridge flash: %s\n", what.c_str());
  return 1;
}

int run_flash(const GlobalOptions& g, const FlashArgs& a) {
  const auto config = a.config_dir.empty() ? usb::default_config_dir() : std::filesystem::path(a.config_dir);
  auto board = find_board(config, a.board);
  if (!board) return fail(board.error().message);
  const auto family = usb::fpga_family(board->fpga);
  if (!board->recipe.present || !family)
    return fail("board \"" + a.board + "\" (" + board->file.string() +
                ") has no \"flash\" section: gpubridge does not know how to program it; use the board's own programmer (docs/boards.md)");

  usb::FlashRequest rq;
  rq.board = board->name;
  rq.family = *family;
  rq.recipe = board->recipe;
  rq.vid = board->vid;
  rq.pid = board->pid;
  // Boards programmed by iceprog wire their configuration flash to the FTDI's channel A (iceprog's
  // default), whichever channel the board's SPI link or UART uses.
  rq.interface = 0;
  rq.serial = a.serial;
  rq.board_serial = board->serial;
  rq.target = a.target == "sram" ? usb::FlashTarget::Sram : usb::FlashTarget::Flash;
  if (!a.tool.empty()) rq.tool = usb::parse_flash_tool(a.tool);

  if (!a.bitstream.empty()) {
    rq.bitstream = a.bitstream;
  } else if (!board->recipe.bitstream.empty()) {
    rq.bitstream = bitstream_dir() / board->recipe.bitstream;
    std::error_code ec;
    if (!std::filesystem::exists(rq.bitstream, ec))
      return fail("no bitstream for " + a.board + " at " + rq.bitstream.string() + ": pass the file (gpubridge flash --board " + a.board +
                  " FILE) or set GPUBRIDGE_BITSTREAM_DIR to the directory holding " + board->recipe.bitstream +
                  "; scripts/gateware.sh --board " + a.board + " builds it from the gateware (docs/boards.md, Flashing)");
  } else {
    return fail("board \"" + a.board + "\" runs a bitstream this project does not build: " + board->recipe.source +
                "; then gpubridge flash --board " + a.board + " FILE");
  }

  auto bytes = read_bitstream(rq.bitstream);
  if (!bytes) return fail(bytes.error().message);
  const auto idcode = *family == usb::FpgaFamily::Ecp5 ? usb::ecp5_idcode(board->fpga) : std::nullopt;
  if (auto ok = usb::check_bitstream(*bytes, *family, idcode, rq.bitstream.string()); !ok)
    return fail(ok.error().message + " (board " + a.board + ": " + board->fpga + ")");

  auto plan = usb::plan_flash(rq, on_path);
  if (!plan) return fail(plan.error().message);
  const std::string exe(usb::executable_of(plan->tool));
  const auto report = [&](const char* result, int code) {
    if (!g.json) return;
    nlohmann::json out{{"board", a.board},
                       {"bitstream", rq.bitstream.string()},
                       {"bitstream_bytes", bytes->size()},
                       {"tool", usb::to_string(plan->tool)},
                       {"target", usb::to_string(plan->target)},
                       {"argv", plan->argv},
                       {"installed", plan->installed},
                       {"result", result}};
    if (code >= 0) out["exit_code"] = code;
    std::puts(json_text(out, 2).c_str());
  };
  if (a.dry_run) {
    if (g.json) report("dry-run", -1);
    else std::printf("%s\n", command_line(plan->argv).c_str());
    return 0;
  }
  if (!plan->installed)
    return fail(exe + " is not installed (not found on PATH): sudo apt-get install " +
                (plan->tool == usb::FlashTool::Iceprog ? std::string("fpga-icestorm") : std::string("openfpgaloader")) +
                " (scripts/install-deps.sh installs both)");
  if (!g.json) std::fprintf(stderr, "gpubridge flash: %s\n", command_line(plan->argv).c_str());
  auto rc = run_programmer(plan->argv);
  if (!rc) return fail(rc.error().message);
  if (*rc != 0) {
    report("failed", *rc);
    return fail(exe + (*rc < 0 ? " was killed by signal " + std::to_string(-*rc) : " failed (exit " + std::to_string(*rc) + ")") +
                ". If it could not open the USB device: install the udev rule (sudo cp configs/udev/70-gpubridge.rules "
                "/etc/udev/rules.d/ && sudo udevadm control --reload, then replug; docs/boards.md). If it found no device: "
                "check the cable, and `gpubridge probe` lists the bridges it sees");
  }
  report("ok", 0);
  if (!g.json)
    std::printf("%s: wrote %s to the %s with %s; next: gpubridge bringup --board %s\n", a.board.c_str(), rq.bitstream.c_str(),
                plan->target == usb::FlashTarget::Flash ? "configuration flash" : "FPGA's SRAM (lost at power-off)", exe.c_str(),
                a.board.c_str());
  return 0;
}

}  // namespace

GPUBRIDGE_COMMAND("flash", 65, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  auto a = std::make_shared<FlashArgs>();
  auto* cmd = app.add_subcommand(
      "flash",
      "program a board with its bitstream through openFPGALoader or iceprog, as its profile's \"flash\" section says "
      "(`gpubridge boards` lists which bitstream goes with which board)");
  cmd->add_option("--board", a->board, "board profile name (configs/boards) or a .json file")->required();
  cmd->add_option("bitstream", a->bitstream,
                  "bitstream file (default: the board's file, `gpubridge boards` names it, in $GPUBRIDGE_BITSTREAM_DIR, else in "
                  "the build tree's gateware/boards/, where scripts/gateware.sh --board NAME writes it)");
  cmd->add_option("--to", a->target, "which memory: flash (kept across power cycles) or sram (a quick load, lost at power-off)")
      ->check(CLI::IsMember({"flash", "sram"}));
  cmd->add_option("--tool", a->tool, "programmer: openfpgaloader or iceprog (default: the first the board offers that is installed)")
      ->check(CLI::IsMember({"openfpgaloader", "iceprog"}));
  cmd->add_option("--serial", a->serial, "USB serial number of the programmer to use when several are attached");
  cmd->add_flag("--dry-run", a->dry_run, "check the bitstream and print the programmer's command line without running it");
  cmd->add_option("--config-dir", a->config_dir, "directory holding boards/ (default: $GPUBRIDGE_CONFIG_DIR or the source tree's configs/)");
  runners.emplace_back(cmd, [&g, a] { return run_flash(g, *a); });
});

}  // namespace gpubridge::cli
