// `gpubridge probe` (which bridges are attached, and with --board the ID register) and
// `gpubridge bringup --board NAME` (ID, register echo, memory test, SPI clock sweep, scenes vs
// the simulator). Both run against an emulated board with --emulate; bringup also against the
// board's Verilated gateware behind the emulated bridge with --rtl.
#include <cstdio>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gpubridge/usb/board_factory.hpp"
#include "gpubridge/usb/bringup.hpp"
#include "gpubridge/usb/emu/rtl_pins.hpp"
#include "gpubridge/usb/hidapi_transport.hpp"
#include "gpubridge/usb/libusb_transport.hpp"
#include "gpubridge/usb/usb_tty.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::cli {
namespace {

struct ProbeArgs {
  std::string board, config_dir;
  bool emulate = false;
};

std::string hex4(std::uint16_t v) {
  char b[8];
  std::snprintf(b, sizeof b, "%04x", v);
  return b;
}

std::filesystem::path config_dir(const std::string& d) { return d.empty() ? usb::default_config_dir() : std::filesystem::path(d); }

// A board on a USB-UART (a DMC-1's standalone SOC): there is no ID to read, as the SOC sends
// nothing back, so probing finds its port from the profile's USB ids.
int probe_uart_board(const GlobalOptions& g, const usb::UartBoardProfile& p) {
  const auto& kind = protocol::device_kind_info(p.device_kind);
  auto port = p.tty.empty() ? usb::find_usb_tty(p.vid, p.pid, p.interface, p.serial) : Result<std::string>(p.tty);
  if (g.json) {
    std::puts(json_text(nlohmann::json{{"board", p.name}, {"device_kind", kind.name}, {"baud", p.baud},
                                       {"tty", port ? *port : ""}, {"problem", port ? "" : port.error().message}},
                        2).c_str());
  } else if (port) {
    std::printf("board %s (%s over a USB-UART at %u baud): port %s; the SOC sends nothing back, so there is no ID to read. "
                "Stream to it: gpubridge render --device %s STREAM --board %s ...\n",
                p.name.c_str(), std::string(kind.label).c_str(), p.baud, port->c_str(), std::string(kind.name).c_str(), p.name.c_str());
  } else {
    std::fprintf(stderr, "gpubridge probe: board %s: %s\n", p.name.c_str(), port.error().message.c_str());
  }
  return port ? 0 : 1;
}

int probe_board(const GlobalOptions& g, const ProbeArgs& a) {
  if (!a.emulate)
    if (auto uart = usb::find_uart_board_profile(config_dir(a.config_dir), a.board)) return probe_uart_board(g, *uart);
  auto profile = usb::find_board_profile(config_dir(a.config_dir), a.board);
  if (!profile) {
    std::fprintf(stderr, "gpubridge probe: %s\n", profile.error().message.c_str());
    return 1;
  }
  usb::BoardOpenOptions o;
  o.emulate = a.emulate;
  auto board = usb::open_board(*profile, o);
  if (!board) {
    std::fprintf(stderr, "gpubridge probe: %s\n", board.error().message.c_str());
    return 1;
  }
  const auto i = (*board)->info();
  if (g.json) {
    nlohmann::json j{{"board", profile->name}, {"bridge", i.bridge}, {"emulated", a.emulate}, {"id", i.id}, {"caps", i.caps},
                     {"caps2", i.caps2}, {"depth_buffer", protocol::has_depth_buffer(i.id, i.caps2)},
                     {"magic_ok", (i.id >> 32) == protocol::kIdMagic}, {"version", {protocol::protocol_major(i.id), protocol::protocol_minor(i.id)}},
                     {"variant", protocol::id_variant(i.id)}, {"vram_bytes", i.vram_bytes}, {"strict_link", (*board)->strict_link()},
                     {"spi_clock_hz", (*board)->bridge().clock_hz()}};
    std::puts(json_text(j, 2).c_str());
  } else {
    std::printf("board %s via %s%s at %.3g MHz: ID 0x%016llX (spigpu v%u.%u, variant 0x%04X), %llu KiB VRAM, %s, strict link %s\n",
                profile->name.c_str(), i.bridge.c_str(), a.emulate ? " (emulated)" : "", (*board)->bridge().clock_hz() / 1e6,
                static_cast<unsigned long long>(i.id), protocol::protocol_major(i.id), protocol::protocol_minor(i.id),
                protocol::id_variant(i.id),
                static_cast<unsigned long long>(i.vram_bytes / 1024),
                protocol::has_depth_buffer(i.id, i.caps2) ? "depth buffer" : "no depth buffer", (*board)->strict_link() ? "on" : "off");
  }
  return 0;
}

int probe_bus(const GlobalOptions& g, const ProbeArgs& a) {
  auto cables = usb::load_cables(config_dir(a.config_dir));
  if (!cables) {
    std::fprintf(stderr, "gpubridge probe: %s\n", cables.error().message.c_str());
    return 1;
  }
  nlohmann::json found = nlohmann::json::array();
  std::string looked_for;
  std::vector<std::pair<std::uint16_t, std::uint16_t>> usb_ids;
  for (const auto& c : *cables) {
    looked_for += (looked_for.empty() ? "" : ", ") + c.name + " " + hex4(c.vid) + ":" + hex4(c.pid);
    if (c.api == "libusb") usb_ids.emplace_back(c.vid, c.pid);
  }
  auto chip_of = [&](std::uint16_t vid, std::uint16_t pid) {
    for (const auto& c : *cables)
      if (c.vid == vid && c.pid == pid) return c.name;
    return std::string("?");
  };
  std::string usb_problem;
  if (a.emulate) {
    for (const auto& c : *cables)
      found.push_back({{"chip", c.name}, {"vid", hex4(c.vid)}, {"pid", hex4(c.pid)}, {"serial", "EMU00001"}, {"port", "emulated"},
                       {"accessible", true}, {"problem", ""}});
  } else {
    auto ctx = usb::LibusbContext::create();
    if (!ctx) {
      usb_problem = ctx.error().message;
    } else if (auto list = (*ctx)->enumerate(usb_ids); !list) {
      usb_problem = list.error().message;
    } else {
      for (const auto& f : *list)
        found.push_back({{"chip", chip_of(f.info.vid, f.info.pid)}, {"vid", hex4(f.info.vid)}, {"pid", hex4(f.info.pid)},
                         {"serial", f.info.serial}, {"port", f.info.port_path}, {"accessible", f.accessible}, {"problem", f.problem}});
    }
    if (auto hid = usb::HidapiContext::create()) {
      for (const auto& c : *cables)
        if (c.api == "hidapi")
          for (const auto& h : (*hid)->enumerate(c.vid, c.pid))
            found.push_back({{"chip", c.name}, {"vid", hex4(h.vid)}, {"pid", hex4(h.pid)}, {"serial", h.serial}, {"port", h.path},
                             {"accessible", true}, {"problem", ""}});
    }
  }
  // USB serial ports, with the UART boards (configs/boards, "uart") whose adapter each one is.
  auto uart_boards = usb::load_uart_board_profiles(config_dir(a.config_dir));
  nlohmann::json serial = nlohmann::json::array();
  for (const auto& t : usb::list_usb_ttys()) {
    nlohmann::json boards = nlohmann::json::array();
    if (uart_boards)
      for (const auto& b : *uart_boards)
        if (b.vid == t.vid && b.pid == t.pid && b.interface == t.interface) boards.push_back(b.name);
    serial.push_back({{"tty", t.path}, {"vid", hex4(t.vid)}, {"pid", hex4(t.pid)}, {"interface", t.interface}, {"serial", t.serial},
                      {"driver", t.driver}, {"boards", boards}});
  }
  if (g.json) {
    std::puts(json_text(nlohmann::json{{"bridges", found}, {"serial_ports", serial}, {"usb_error", usb_problem}, {"looked_for", looked_for}},
                        2).c_str());
    return usb_problem.empty() ? 0 : 1;
  }
  if (!serial.empty()) {
    std::printf("%-14s %-10s %-5s %-10s %-16s %s\n", "SERIAL PORT", "VID:PID", "IFACE", "DRIVER", "SERIAL", "BOARDS");
    for (const auto& t : serial) {
      std::string boards;
      for (const auto& b : t["boards"]) boards += (boards.empty() ? "" : ", ") + b.get<std::string>();
      std::printf("%-14s %s:%s %-5d %-10s %-16s %s\n", t["tty"].get<std::string>().c_str(), t["vid"].get<std::string>().c_str(),
                  t["pid"].get<std::string>().c_str(), t["interface"].get<int>(), t["driver"].get<std::string>().c_str(),
                  t["serial"].get<std::string>().c_str(), boards.c_str());
    }
  }
  if (!usb_problem.empty()) std::fprintf(stderr, "gpubridge probe: cannot scan USB: %s\n", usb_problem.c_str());
  if (found.empty()) {
    std::printf("No USB-SPI bridges found (looked for %s).\nPlug one in, check `lsusb`, or try an emulated board: gpubridge probe --emulate --board ft232h-generic\n",
                looked_for.c_str());
    return usb_problem.empty() ? 0 : 1;
  }
  std::printf("%-8s %-10s %-16s %-12s %s\n", "CHIP", "VID:PID", "SERIAL", "PORT", "STATUS");
  for (const auto& f : found)
    std::printf("%-8s %s:%s %-16s %-12s %s\n", f["chip"].get<std::string>().c_str(), f["vid"].get<std::string>().c_str(),
                f["pid"].get<std::string>().c_str(), f["serial"].get<std::string>().c_str(), f["port"].get<std::string>().c_str(),
                f["accessible"].get<bool>() ? (f["problem"].get<std::string>().empty() ? "ok" : f["problem"].get<std::string>().c_str())
                                            : f["problem"].get<std::string>().c_str());
  return 0;
}

struct BringupArgs {
  ProbeArgs probe;
  usb::BringupOptions opts;
  std::uint32_t emulated_limit = 0;
  bool rtl = false;  // the board's gateware, co-simulated, behind the emulated bridge chip
};

int run_bringup(const GlobalOptions& g, const BringupArgs& a) {
  auto profile = usb::find_board_profile(config_dir(a.probe.config_dir), a.probe.board);
  if (!profile) {
    std::fprintf(stderr, "gpubridge bringup: %s\n", profile.error().message.c_str());
    return 1;
  }
  usb::BoardOpenOptions o;
  o.emulate = a.probe.emulate || a.rtl;
  if (a.rtl) o.emulated_pins = usb::emu::rtl_pins();
  o.emulated_max_reliable_hz = a.emulated_limit;
  const char* kind = a.rtl ? " (gateware co-simulation)" : a.probe.emulate ? " (emulated)" : "";
  // Attach at a conservative clock: the sweep finds how fast this board really goes.
  usb::BringupOptions opts = a.opts;
  opts.max_clock_hz = profile->spi_clock_hz;
  profile->spi_clock_hz = std::min<std::uint32_t>(profile->spi_clock_hz, 1'000'000);
  auto board = usb::open_board(*profile, o);
  if (!board) {
    std::fprintf(stderr, "gpubridge bringup: %s\n", board.error().message.c_str());
    return 1;
  }
  // Progress only on a terminal; scripts and logs get the report alone.
  if (!g.json && ::isatty(2)) opts.progress = [](const std::string& step, unsigned pct) { std::fprintf(stderr, "\r%s: %3u%%", step.c_str(), pct); if (pct >= 100) std::fputc('\n', stderr); };
  const auto rep = usb::run_bringup(**board, opts);
  if (g.json) {
    nlohmann::json steps = nlohmann::json::array();
    for (const auto& s : rep.steps)
      steps.push_back({{"name", s.name}, {"ok", s.ok}, {"skipped", s.skipped}, {"detail", s.detail}, {"seconds", s.seconds}});
    const nlohmann::json report{{"board", profile->name}, {"emulated", o.emulate}, {"gateware", a.rtl}, {"ok", rep.ok()},
                                {"best_clock_hz", rep.best_clock_hz}, {"steps", steps}};
    std::puts(json_text(report, 2).c_str());
  } else {
    std::printf("bring-up of %s%s\n", profile->name.c_str(), kind);
    for (const auto& s : rep.steps)
      std::printf("  %-14s %-5s %s\n", s.name.c_str(), s.skipped ? "skip" : s.ok ? "ok" : "FAIL", s.detail.c_str());
    std::printf("%s\n", rep.ok() ? "PASS" : "FAIL");
  }
  return rep.ok() ? 0 : 1;
}

}  // namespace

GPUBRIDGE_COMMAND("probe", 71, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  auto a = std::make_shared<ProbeArgs>();
  auto* probe = app.add_subcommand("probe", "list attached USB-SPI bridges (chip, VID:PID, serial, port, access) and USB serial ports (UART boards such as icebreaker-dmc1); with --board read the ID register (a UART board: find its port)");
  probe->add_option("--board", a->board, "board profile name (configs/boards) or a .json file: open it and read ID/CAPS");
  probe->add_flag("--emulate", a->emulate, "use the emulated bridge chip and simulator instead of USB hardware");
  probe->add_option("--config-dir", a->config_dir, "directory holding boards/ and cables/");
  runners.emplace_back(probe, [&g, a] { return a->board.empty() ? probe_bus(g, *a) : probe_board(g, *a); });

  auto b = std::make_shared<BringupArgs>();
  auto* bringup = app.add_subcommand("bringup", "bring up a board: ID, register echo, memory test, SPI clock sweep, scenes vs the simulator");
  bringup->add_option("--board", b->probe.board, "board profile name or .json file")->required();
  bringup->add_flag("--emulate", b->probe.emulate, "run against the emulated bridge chip and simulator");
  bringup->add_flag("--rtl", b->rtl,
                    "run against the board's gateware (Verilated, docs/gateware.md) behind the emulated bridge chip")
      ->excludes("--emulate");
  bringup->add_option("--config-dir", b->probe.config_dir, "directory holding boards/ and cables/");
  bringup->add_option("--mem-base", b->opts.mem_base, "memory test start address")->capture_default_str();
  bringup->add_option("--mem-bytes", b->opts.mem_bytes, "memory test length in bytes (clamped to video memory)")
      ->capture_default_str()
      ->check(CLI::Range(8u, 1u << 30));
  bringup->add_option("--iterations", b->opts.clock_iterations, "passes per SPI clock in the sweep")
      ->capture_default_str()
      ->check(CLI::Range(1u, 10000u));
  bringup->add_option("--clock", b->opts.clocks, "SPI clocks to try in Hz, highest first (default: a ladder up to the profile's clock)");
  bringup->add_flag("--readback", b->opts.readback, "also compare scene pixels (not only FRAME_CRC)");
  bringup->add_option("--diff-dir", b->opts.diff_dir, "with --readback: write <scene>-diff.png here on mismatch");
  bringup->add_option("--emulate-max-clock", b->emulated_limit, "emulation only: SPI bit errors above this clock (tests the sweep)");
  runners.emplace_back(bringup, [&g, b] { return run_bringup(g, *b); });
});

}  // namespace gpubridge::cli
