// The daemon's backend kinds, one row each in kKinds: the one place that knows backend names.
// make_backend, check_backend, is_board_backend, make_reattach_factory, watch_board_usb and
// fallback_factory all resolve a name to its row once and ask the row.
#include "gpubridge/daemon/backend_factory.hpp"

#include <cstdio>

#include "gpubridge/common/log.hpp"
#include "gpubridge/dmc1/dmc1_backend.hpp"
#include "gpubridge/dmc1/serial_link.hpp"
#include "gpubridge/rtl/rtl_device.hpp"
#include "gpubridge/daemon/test_backends.hpp"
#include "gpubridge/sim/sim_backend.hpp"
#include "gpubridge/usb/board_factory.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/emu/rtl_pins.hpp"
#include "gpubridge/usb/hotplug_monitor.hpp"
#include "gpubridge/usb/usb_tty.hpp"

namespace gpubridge::daemon {

namespace {

using BackendPtr = std::unique_ptr<backends::Backend>;

// ---- what the rows do --------------------------------------------------------------------

// `boards_dir` may name the configuration directory (holding boards/) or the boards/ directory
// itself; the USB library wants the former.
std::filesystem::path config_dir_of(const DaemonConfig& cfg) {
  if (cfg.boards_dir.empty()) return usb::default_config_dir();
  const std::filesystem::path dir(cfg.boards_dir);
  std::error_code ec;
  if (std::filesystem::is_directory(dir / "boards", ec)) return dir;
  return dir.lexically_normal().parent_path();
}

Result<std::pair<unsigned, unsigned>> parse_fake_size(std::string_view size) {
  unsigned w = 0, h = 0;
  char x = 0;
  const std::string text(size);
  if (std::sscanf(text.c_str(), "%u%c%u", &w, &x, &h) != 3 || x != 'x' || w < 1 || h < 1 ||
      w > protocol::kMaxFramebufferDim || h > protocol::kMaxFramebufferDim)
    return make_error("backend \"fake:" + text + "\": expected fake:WIDTHxHEIGHT with sizes 1..1024");
  return std::pair{w, h};
}

// "emulated:PROFILE?presence=PATH": options after '?' (key=value, '&'-separated) configure the
// emulation; today only `presence` (the emulated adapter is plugged in while PATH exists).
struct EmulatedSpec {
  std::string profile;
  std::string presence_file;
};

Result<EmulatedSpec> parse_emulated_spec(std::string_view spec_view) {
  const std::string spec(spec_view);
  EmulatedSpec out;
  const auto q = spec.find('?');
  out.profile = spec.substr(0, q);
  if (out.profile.empty())
    return make_error("backend \"emulated:" + spec +
                      "\": expected emulated:PROFILE (a board profile name or .json file), optionally ?presence=PATH");
  if (q == std::string::npos) return out;
  std::string rest = spec.substr(q + 1);
  while (!rest.empty()) {
    const auto amp = rest.find('&');
    const std::string item = rest.substr(0, amp);
    rest = amp == std::string::npos ? "" : rest.substr(amp + 1);
    const auto eq = item.find('=');
    const std::string key = item.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    if (key == "presence" && !value.empty()) {
      out.presence_file = value;
    } else {
      return make_error("backend \"emulated:" + spec + "\": unknown option \"" + item +
                        "\" (the only option is presence=PATH: the emulated adapter is plugged in while PATH exists)");
    }
  }
  return out;
}

Result<usb::BoardProfile> named_profile(const std::string& backend, const std::string& profile_name, const DaemonConfig& cfg) {
  auto profile = usb::find_board_profile(config_dir_of(cfg), profile_name);
  if (!profile) return make_error("backend \"" + backend + "\": " + profile.error().message);
  return profile;
}

// What sits behind the board's driver: the real adapter, its bridge chip's model driving the
// simulator, or its bridge chip's model driving the board's Verilated gateware (rtl:BOARD).
enum class Attach { Real, Emulated, Gateware };

std::string_view attach_note(Attach a) {
  return a == Attach::Gateware ? ", gateware co-simulated" : a == Attach::Emulated ? ", emulated" : "";
}

Result<BackendPtr> open_board(const usb::BoardProfile& profile, Attach attach, const std::string& presence_file = {}) {
  usb::BoardOpenOptions opts;
  opts.emulate = attach != Attach::Real;
  opts.emulated_presence_file = presence_file;
  if (attach == Attach::Gateware) opts.emulated_pins = usb::emu::rtl_pins();
  auto board = usb::open_board(profile, opts);
  if (!board) {
    std::string msg = "board \"" + profile.name + "\" (" + std::string(usb::to_string(profile.chip)) + ")" +
                      (attach == Attach::Gateware ? " (gateware co-simulation)" : attach == Attach::Emulated ? " (emulated)" : "") +
                      ": " + board.error().message;
    if (attach == Attach::Real)
      msg += "; or run without it: --backend sim (simulator) or --backend emulated:" + profile.name +
             " (this board's driver against an emulated bridge)";
    return make_error(msg, board.error().code);
  }
  logger("daemon")->info("backend: board {} ({}){}", profile.name, usb::to_string(profile.chip), attach_note(attach));
  return BackendPtr(std::move(*board));
}

std::string describe_board(const usb::BoardProfile& profile, Attach attach, const DaemonConfig& cfg) {
  const std::string gateware = attach == Attach::Gateware ? ", gateware " + profile.gateware + " co-simulated" : "";
  return "board " + profile.name + " (" + std::string(usb::to_string(profile.chip)) +
         (attach == Attach::Emulated ? ", emulated" : "") + gateware + ") from " + profile.file.string() +
         (cfg.mirror ? ", mirrored by the simulator" : "");
}

// The first board whose real bridge opens and attaches; nullptr when none does. Profiles whose
// bridge is absent fail at the USB open (no transfers), so this stays fast without hardware.
BackendPtr first_present_board(const DaemonConfig& cfg) {
  auto log = logger("daemon");
  auto profiles = usb::load_board_profiles(config_dir_of(cfg));
  if (!profiles) {
    log->debug("auto: no board profiles: {}", profiles.error().message);
    return nullptr;
  }
  for (const auto& p : *profiles) {
    auto board = usb::open_board(p, usb::BoardOpenOptions{});
    if (board) {
      log->info("auto: using board {} ({})", p.name, usb::to_string(p.chip));
      return std::move(*board);
    }
    log->debug("auto: skipped board {}: {}", p.name, board.error().message);
  }
  return nullptr;
}

// sim
Result<BackendPtr> open_sim(std::string_view, const DaemonConfig& cfg) { return make_simulator(cfg); }
Result<std::string> describe_sim(std::string_view, const DaemonConfig&) { return std::string("the simulator"); }

// discard
Result<BackendPtr> open_discard(std::string_view, const DaemonConfig&) { return BackendPtr(std::make_unique<DiscardBackend>()); }
Result<std::string> describe_discard(std::string_view, const DaemonConfig&) {
  return std::string("discard (accepts every command, scans out nothing)");
}

// fake, fake:WxH (frames of that size: fan-out and memory tests); `size` is "" or ":WxH"
Result<BackendPtr> open_fake(std::string_view size, const DaemonConfig&) {
  if (size.empty()) return BackendPtr(std::make_unique<FakeScanoutBackend>());
  auto wh = parse_fake_size(size.substr(1));
  if (!wh) return wh.error();
  return BackendPtr(std::make_unique<FakeScanoutBackend>(wh->first, wh->second));
}
Result<std::string> describe_fake(std::string_view size, const DaemonConfig&) {
  if (size.empty()) return std::string("fake (test backend: registers, 1 MiB of memory, 64x48 frames)");
  auto wh = parse_fake_size(size.substr(1));
  if (!wh) return wh.error();
  return "fake (test backend, " + std::to_string(wh->first) + "x" + std::to_string(wh->second) + " frames)";
}

// auto: the first present board, else the simulator
Result<std::vector<usb::BoardProfile>> profiles_auto(std::string_view, const DaemonConfig& cfg) {
  auto profiles = usb::load_board_profiles(config_dir_of(cfg));
  if (!profiles) return make_error("backend \"auto\": " + profiles.error().message);
  return profiles;
}
Result<BackendPtr> open_auto(std::string_view, const DaemonConfig& cfg) {
  if (auto board = first_present_board(cfg)) return board;
  logger("daemon")->info("auto: no board attached (details at --log-level debug); using the simulator");
  return make_simulator(cfg);
}
Result<BackendPtr> reopen_auto(std::string_view, const DaemonConfig& cfg) {  // never settles for the simulator
  if (auto board = first_present_board(cfg)) return board;
  return make_error("auto: no board attached", backends::kDeviceGone);
}
Result<std::string> describe_auto(std::string_view, const DaemonConfig& cfg) {
  auto profiles = profiles_auto({}, cfg);
  if (!profiles) return profiles.error();
  const std::string first = "auto: the first of " + std::to_string(profiles->size()) + " board profiles in " +
                            (config_dir_of(cfg) / "boards").string() + " whose adapter is present";
  if (cfg.mirror) return first + ", mirrored by the simulator (with --mirror the daemon does not start when none is present)";
  return first + ", else the simulator" + (cfg.reattach_interval_ms ? " until a board is plugged in" : "");
}

// emulated:PROFILE[?presence=PATH]: the board's driver on its bridge chip's model + the simulator
Result<std::vector<usb::BoardProfile>> profiles_emulated(std::string_view spec, const DaemonConfig& cfg) {
  auto s = parse_emulated_spec(spec);
  if (!s) return s.error();
  auto profile = named_profile("emulated:" + std::string(spec), s->profile, cfg);
  if (!profile) return profile.error();
  return std::vector<usb::BoardProfile>{std::move(*profile)};
}
Result<BackendPtr> open_emulated(std::string_view spec, const DaemonConfig& cfg) {
  auto s = parse_emulated_spec(spec);
  if (!s) return s.error();
  auto profile = named_profile("emulated:" + s->profile, s->profile, cfg);
  if (!profile) return profile.error();
  return open_board(*profile, Attach::Emulated, s->presence_file);
}
Result<std::string> describe_emulated(std::string_view spec, const DaemonConfig& cfg) {
  auto profiles = profiles_emulated(spec, cfg);
  if (!profiles) return profiles.error();
  return describe_board(profiles->front(), Attach::Emulated, cfg);
}

// rtl:BOARD: the board's driver on its bridge chip's model, in front of the board's gateware
// Verilated (docs/gateware.md); needs Verilator in the build and a profile naming its gateware.
Result<usb::BoardProfile> rtl_profile(std::string_view board, const DaemonConfig& cfg) {
  const std::string backend = "rtl:" + std::string(board);
  if (!rtl::RtlDevice::available()) return make_error("backend \"" + backend + "\": " + rtl::RtlDevice::unavailable_reason());
  auto profile = named_profile(backend, std::string(board), cfg);
  if (!profile) return profile.error();
  if (profile->gateware.empty())
    return make_error("backend \"" + backend + "\": board profile " + profile->file.string() +
                      " names no gateware; add \"gateware\": {\"profile\": \"up5k\"} (or \"ecp5\") for the design it runs");
  return profile;
}
Result<BackendPtr> open_rtl(std::string_view board, const DaemonConfig& cfg) {
  auto profile = rtl_profile(board, cfg);
  if (!profile) return profile.error();
  return open_board(*profile, Attach::Gateware);
}
Result<std::string> describe_rtl(std::string_view board, const DaemonConfig& cfg) {
  auto profile = rtl_profile(board, cfg);
  if (!profile) return profile.error();
  return describe_board(*profile, Attach::Gateware, cfg);
}

// dmc1: the DMC-1 simulator. Its texture image and palette come from the configuration, else from
// the data the repository's DMC-1 streams were made with (GPUBRIDGE_DMC1_DATA_DIR overrides where
// that is).
std::filesystem::path dmc1_data_dir() {
  if (const char* env = std::getenv("GPUBRIDGE_DMC1_DATA_DIR"); env && *env) return env;
  return GPUBRIDGE_DMC1_DEFAULT_DATA_DIR;
}
std::filesystem::path dmc1_textures_of(const DaemonConfig& cfg) {
  return cfg.dmc1_textures.empty() ? dmc1_data_dir() / "textures.bin.gz" : std::filesystem::path(cfg.dmc1_textures);
}
std::filesystem::path dmc1_palette_of(const DaemonConfig& cfg) {
  return cfg.dmc1_palette.empty() ? dmc1_data_dir() / "palette.bin" : std::filesystem::path(cfg.dmc1_palette);
}
std::string dmc1_data_text(const DaemonConfig& cfg) {
  return "textures " + dmc1_textures_of(cfg).string() + ", palette " + dmc1_palette_of(cfg).string();
}

Result<BackendPtr> open_dmc1_device(const DaemonConfig& cfg, std::unique_ptr<dmc1::SerialLink> link, const std::string& board) {
  const std::string hint = " (set --dmc1-textures FILE --dmc1-palette FILE, or dmc1_textures / dmc1_palette in the configuration)";
  auto textures = dmc1::load_texture_memory(dmc1_textures_of(cfg));
  if (!textures) return make_error("backend dmc1: " + textures.error().message + hint);
  auto palette = dmc1::load_palette(dmc1_palette_of(cfg));
  if (!palette) return make_error("backend dmc1: " + palette.error().message + hint);
  dmc1::Dmc1BackendOptions opts;
  opts.board = board;
  auto b = dmc1::Dmc1Backend::create(std::move(*textures), *palette, opts, std::move(link));
  if (!b) return make_error("backend dmc1: " + b.error().message);
  logger("daemon")->info("backend: DMC-1 {}{} ({})", board.empty() ? "simulator" : "board " + board,
                         board.empty() ? "" : ", showing the simulator's frames", dmc1_data_text(cfg));
  return BackendPtr(std::move(*b));
}
Result<BackendPtr> open_dmc1(std::string_view, const DaemonConfig& cfg) { return open_dmc1_device(cfg, nullptr, {}); }
Result<std::string> describe_dmc1(std::string_view, const DaemonConfig& cfg) {
  for (const auto& f : {dmc1_textures_of(cfg), dmc1_palette_of(cfg)}) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(f, ec))
      return make_error("backend dmc1: " + f.string() + " is not a file (set --dmc1-textures / --dmc1-palette)");
  }
  return "the DMC-1 simulator (" + dmc1_data_text(cfg) + ")";
}

// A UART board profile (device_kind dmc1, e.g. icebreaker-dmc1): the board over its USB-UART, with
// the DMC-1 simulator computing the frames it cannot send back. nullopt: `name` is no UART board.
std::optional<usb::UartBoardProfile> uart_board(std::string_view name, const DaemonConfig& cfg) {
  auto p = usb::find_uart_board_profile(config_dir_of(cfg), std::string(name));
  if (!p) return std::nullopt;
  return std::move(*p);
}
Result<BackendPtr> open_uart_board(const usb::UartBoardProfile& profile, const DaemonConfig& cfg) {
  std::string tty = profile.tty;
  if (tty.empty()) {
    auto found = usb::find_usb_tty(profile.vid, profile.pid, profile.interface, profile.serial);
    if (!found) return make_error("board \"" + profile.name + "\": " + found.error().message + "; or run without it: --backend dmc1 (the DMC-1 simulator)",
                                  backends::kDeviceGone);
    tty = *found;
  }
  auto link = dmc1::SerialLink::open(tty, profile.baud);
  if (!link) return make_error("board \"" + profile.name + "\": " + link.error().message, backends::kDeviceGone);
  return open_dmc1_device(cfg, std::move(*link), profile.name);
}
std::string describe_uart_board(const usb::UartBoardProfile& profile, const DaemonConfig& cfg) {
  return "board " + profile.name + " (" + std::string(protocol::device_kind_info(profile.device_kind).label) +
         " over a USB-UART at " + std::to_string(profile.baud) + " baud" +
         (profile.tty.empty() ? "" : ", " + profile.tty) + ") from " + profile.file.string() +
         ", showing the DMC-1 simulator's frames (" + dmc1_data_text(cfg) + ")";
}

// BOARD: a board profile name or .json file, the real board
Result<std::vector<usb::BoardProfile>> profiles_board(std::string_view name, const DaemonConfig& cfg) {
  if (uart_board(name, cfg)) return std::vector<usb::BoardProfile>{};  // a tty: no libusb notifications to watch
  auto profile = named_profile(std::string(name), std::string(name), cfg);
  if (!profile) return profile.error();
  return std::vector<usb::BoardProfile>{std::move(*profile)};
}
Result<BackendPtr> open_real_board(std::string_view name, const DaemonConfig& cfg) {
  if (auto uart = uart_board(name, cfg)) return open_uart_board(*uart, cfg);
  auto profile = named_profile(std::string(name), std::string(name), cfg);
  if (!profile) return profile.error();
  return open_board(*profile, Attach::Real);
}
Result<std::string> describe_real_board(std::string_view name, const DaemonConfig& cfg) {
  if (auto uart = uart_board(name, cfg)) return describe_uart_board(*uart, cfg);
  auto profiles = profiles_board(name, cfg);
  if (!profiles) return profiles.error();
  return describe_board(profiles->front(), Attach::Real, cfg);
}

// ---- the table ---------------------------------------------------------------------------

// What follows a kind's name: nothing ("sim"), an optional ":ARG" ("fake", "fake:64x48": the row
// gets "" or ":64x48"), a required ":ARG" ("emulated:BOARD": the row gets "BOARD"), or the whole
// name (the last row, a board profile).
enum class Arg : std::uint8_t { None, Optional, Required, WholeName };

struct BackendKind {
  std::string_view name;
  Arg arg;
  std::string_view syntax;  // for --help
  bool board;               // names a board: can disappear (then the simulator may take over) and come back, can be mirrored
  bool usb_watch;           // a real USB adapter: libusb hot-plug notifications apply
  Result<BackendPtr> (*open)(std::string_view arg, const DaemonConfig& cfg);
  // What `open` would serve, checked without opening a device (--check-config).
  Result<std::string> (*describe)(std::string_view arg, const DaemonConfig& cfg);
  // Board kinds with usb_watch: the profiles whose USB ids to watch.
  Result<std::vector<usb::BoardProfile>> (*profiles)(std::string_view arg, const DaemonConfig& cfg) = nullptr;
  // Board kinds: re-opens after an unplug (nullptr: `open` again).
  Result<BackendPtr> (*reopen)(std::string_view arg, const DaemonConfig& cfg) = nullptr;
};

// clang-format off
constexpr BackendKind kKinds[] = {
  // name        arg             syntax                            board  usb_watch
  {"sim",      Arg::None,      "sim",                            false, false, &open_sim,        &describe_sim},
  {"auto",     Arg::None,      "auto",                           true,  true,  &open_auto,       &describe_auto,       &profiles_auto, &reopen_auto},
  {"emulated", Arg::Required,  "emulated:BOARD[?presence=PATH]", true,  false, &open_emulated,   &describe_emulated},
  {"rtl",      Arg::Required,  "rtl:BOARD",                      true,  false, &open_rtl,        &describe_rtl},
  {"fake",     Arg::Optional,  "fake[:WIDTHxHEIGHT]",            false, false, &open_fake,       &describe_fake},
  {"discard",  Arg::None,      "discard",                        false, false, &open_discard,    &describe_discard},
  {"dmc1",     Arg::None,      "dmc1",                           false, false, &open_dmc1,       &describe_dmc1},
  {"",         Arg::WholeName, "BOARD",                          true,  true,  &open_real_board, &describe_real_board, &profiles_board},
};
// clang-format on
static_assert(kKinds[std::size(kKinds) - 1].arg == Arg::WholeName, "the last row takes every other name");

struct Resolved {
  const BackendKind& kind;
  std::string_view arg;
};

Resolved resolve(std::string_view name) {
  for (const auto& k : kKinds) {
    if (k.arg == Arg::WholeName) return {k, name};
    if (!name.starts_with(k.name)) continue;
    const auto rest = name.substr(k.name.size());
    if (rest.empty() && k.arg != Arg::Required) return {k, rest};
    if (rest.starts_with(':') && k.arg == Arg::Optional) return {k, rest};
    if (rest.starts_with(':') && k.arg == Arg::Required) return {k, rest.substr(1)};
  }
  return {kKinds[std::size(kKinds) - 1], name};
}

}  // namespace

std::string backend_syntax() {
  std::string out;
  for (const auto& k : kKinds) out += (out.empty() ? "" : " | ") + std::string(k.syntax);
  return out;
}

Result<BackendPtr> make_simulator(const DaemonConfig& cfg) {
  sim::DeviceOptions o;
  auto knobs = sim::parse_knobs(cfg.accuracy);
  if (!knobs) return make_error("accuracy (--accuracy): " + knobs.error().message);
  o.accuracy = *knobs;
  auto sim = sim::SimBackend::create(o);
  if (!sim) return sim.error();
  return BackendPtr(std::move(*sim));
}

Result<BackendPtr> make_backend(const std::string& name, const DaemonConfig& cfg) {
  const auto r = resolve(name);
  return r.kind.open(r.arg, cfg);
}

Result<std::string> check_backend(const DaemonConfig& cfg) {
  const auto r = resolve(cfg.backend);
  if (cfg.mirror && uart_board(cfg.backend, cfg))
    return make_error("--mirror needs an spigpu board; \"" + cfg.backend +
                      "\" is a DMC-1 board, whose frames are already the simulator's (it sends none back)");
  if (cfg.mirror && !r.kind.board)
    return make_error("--mirror needs a board backend (a board profile name, emulated:BOARD, rtl:BOARD or auto), not \"" + cfg.backend +
                      "\": mirror mode compares a board with the simulator");
  return r.kind.describe(r.arg, cfg);
}

bool is_board_backend(const std::string& name) { return resolve(name).kind.board; }

std::function<Result<BackendPtr>()> fallback_factory(const DaemonConfig& cfg) {
  if (!cfg.fallback_to_sim || !resolve(cfg.backend).kind.board) return {};  // only boards disappear
  // A DMC-1 board falls back to nothing: the spigpu simulator would change the device kind under
  // its clients (DEVICE_GONE, then the board again when its port comes back).
  if (uart_board(cfg.backend, cfg)) return {};
  return [cfg] { return make_simulator(cfg); };
}

std::function<Result<BackendPtr>()> make_reattach_factory(const DaemonConfig& cfg) {
  const auto r = resolve(cfg.backend);
  if (!r.kind.board) return {};
  // Copies of the name and configuration: the factory runs later, on the device thread.
  return [&kind = r.kind, name = cfg.backend, cfg]() -> Result<BackendPtr> {
    const auto arg = resolve(name).arg;
    return kind.reopen ? kind.reopen(arg, cfg) : kind.open(arg, cfg);
  };
}

Result<std::shared_ptr<void>> watch_board_usb(const DaemonConfig& cfg, std::function<void()> on_event) {
  const auto r = resolve(cfg.backend);
  if (!r.kind.usb_watch || cfg.reattach_interval_ms == 0) return std::shared_ptr<void>();
  auto profiles = r.kind.profiles(r.arg, cfg);
  if (!profiles) return profiles.error();
  std::vector<std::pair<std::uint16_t, std::uint16_t>> ids;
  for (const auto& p : *profiles) ids.emplace_back(p.vid, p.pid);
  if (ids.empty()) return std::shared_ptr<void>();
  auto monitor = usb::HotplugMonitor::start(ids, [on_event = std::move(on_event)](bool, std::uint16_t, std::uint16_t) { on_event(); });
  if (!monitor) return monitor.error();
  return std::shared_ptr<void>(std::move(*monitor));
}

}  // namespace gpubridge::daemon
