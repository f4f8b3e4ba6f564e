#include "gpubridge/daemon/backend_factory.hpp"

#include <cstdio>

#include "gpubridge/common/log.hpp"
#include "gpubridge/daemon/test_backends.hpp"

#ifdef GPUBRIDGE_HAVE_SIM
#include "gpubridge/sim/sim_backend.hpp"
#endif
#ifdef GPUBRIDGE_HAVE_USB
#include "gpubridge/usb/board_factory.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/hotplug_monitor.hpp"
#endif

namespace gpubridge::daemon {

namespace {
constexpr std::string_view kEmulatedPrefix = "emulated:";

Result<std::pair<unsigned, unsigned>> parse_fake_size(const std::string& name) {
  unsigned w = 0, h = 0;
  char x = 0;
  if (std::sscanf(name.c_str() + 5, "%u%c%u", &w, &x, &h) != 3 || x != 'x' || w < 1 || h < 1 ||
      w > protocol::kMaxFramebufferDim || h > protocol::kMaxFramebufferDim)
    return make_error("backend \"" + name + "\": expected fake:WIDTHxHEIGHT with sizes 1..1024");
  return std::pair{w, h};
}

#ifdef GPUBRIDGE_HAVE_USB
// `boards_dir` may name the configuration directory (holding boards/) or the boards/ directory
// itself; the USB library wants the former.
std::filesystem::path config_dir_of(const DaemonConfig& cfg) {
  if (cfg.boards_dir.empty()) return usb::default_config_dir();
  const std::filesystem::path dir(cfg.boards_dir);
  std::error_code ec;
  if (std::filesystem::is_directory(dir / "boards", ec)) return dir;
  return dir.lexically_normal().parent_path();
}

// "emulated:PROFILE?presence=PATH": options after '?' (key=value, '&'-separated) configure the
// emulation; today only `presence` (the emulated adapter is plugged in while PATH exists).
struct EmulatedSpec {
  std::string profile;
  std::string presence_file;
};

Result<EmulatedSpec> parse_emulated_spec(const std::string& spec) {
  EmulatedSpec out;
  const auto q = spec.find('?');
  out.profile = spec.substr(0, q);
  if (out.profile.empty())
    return make_error("backend \"" + std::string(kEmulatedPrefix) + spec +
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
      return make_error("backend \"" + std::string(kEmulatedPrefix) + spec + "\": unknown option \"" + item +
                        "\" (the only option is presence=PATH: the emulated adapter is plugged in while PATH exists)");
    }
  }
  return out;
}

// The profiles a board backend name stands for: every profile for "auto", else the one it names
// ("emulated:NAME?..." names NAME). Used where no device is opened (--check-config, the USB watch).
Result<std::vector<usb::BoardProfile>> board_profiles_of(const DaemonConfig& cfg, const std::string& name) {
  if (name == "auto") {
    auto profiles = usb::load_board_profiles(config_dir_of(cfg));
    if (!profiles) return make_error("backend \"auto\": " + profiles.error().message);
    return profiles;
  }
  std::string profile_name = name;
  if (name.starts_with(kEmulatedPrefix)) {
    auto spec = parse_emulated_spec(name.substr(kEmulatedPrefix.size()));
    if (!spec) return spec.error();
    profile_name = spec->profile;
  }
  auto profile = usb::find_board_profile(config_dir_of(cfg), profile_name);
  if (!profile) return make_error("backend \"" + name + "\": " + profile.error().message);
  return std::vector<usb::BoardProfile>{std::move(*profile)};
}

Result<std::unique_ptr<backends::Backend>> open_named_board(const std::string& name, bool emulate, const DaemonConfig& cfg,
                                                             const std::string& presence_file = {}) {
  auto profile = usb::find_board_profile(config_dir_of(cfg), name);
  if (!profile) return make_error("backend \"" + std::string(emulate ? kEmulatedPrefix : "") + name + "\": " + profile.error().message);
  usb::BoardOpenOptions opts;
  opts.emulate = emulate;
  opts.emulated_presence_file = presence_file;
  auto board = usb::open_board(*profile, opts);
  if (!board) {
    std::string msg = "board \"" + profile->name + "\" (" + std::string(usb::to_string(profile->chip)) + ")" +
                      (emulate ? " (emulated)" : "") + ": " + board.error().message;
    if (!emulate)
      msg += "; or run without it: --backend sim (simulator) or --backend emulated:" + profile->name +
             " (this board's driver against an emulated bridge)";
    return make_error(msg, board.error().code);
  }
  logger("daemon")->info("backend: board {} ({}){}", profile->name, usb::to_string(profile->chip), emulate ? ", emulated" : "");
  return std::unique_ptr<backends::Backend>(std::move(*board));
}

// The first board whose real bridge opens and attaches; nullptr when none does. Profiles whose
// bridge is absent fail at the USB open (no transfers), so this stays fast without hardware.
std::unique_ptr<backends::Backend> first_present_board(const DaemonConfig& cfg) {
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
#endif
}  // namespace

bool simulator_available() {
#ifdef GPUBRIDGE_HAVE_SIM
  return true;
#else
  return false;
#endif
}

Result<std::unique_ptr<backends::Backend>> make_simulator() {
#ifdef GPUBRIDGE_HAVE_SIM
  auto sim = sim::SimBackend::create();
  if (!sim) return sim.error();
  return std::unique_ptr<backends::Backend>(std::move(*sim));
#else
  return make_error("this gpubridged was built without the simulator (gpubridge_sim); use --backend fake or discard");
#endif
}

Result<std::unique_ptr<backends::Backend>> make_backend(const std::string& name, const DaemonConfig& cfg) {
  if (name == "sim") return make_simulator();
  if (name == "discard") return std::unique_ptr<backends::Backend>(std::make_unique<DiscardBackend>());
  if (name == "fake") return std::unique_ptr<backends::Backend>(std::make_unique<FakeScanoutBackend>());
  if (name.starts_with("fake:")) {  // fake:WxH, frames of that size (fan-out and memory tests)
    auto size = parse_fake_size(name);
    if (!size) return size.error();
    return std::unique_ptr<backends::Backend>(std::make_unique<FakeScanoutBackend>(size->first, size->second));
  }
#ifdef GPUBRIDGE_HAVE_USB
  if (name == "auto") {
    if (auto board = first_present_board(cfg)) return board;
    logger("daemon")->info("auto: no board attached (details at --log-level debug); using the simulator");
    return make_simulator();
  }
  if (name.starts_with(kEmulatedPrefix)) {
    auto spec = parse_emulated_spec(name.substr(kEmulatedPrefix.size()));
    if (!spec) return spec.error();
    return open_named_board(spec->profile, true, cfg, spec->presence_file);
  }
  return open_named_board(name, false, cfg);
#else
  (void)cfg;
  if (name == "auto") return make_simulator();  // no USB board path: nothing to detect
  return make_error("backend \"" + name +
                    "\": board backends need the USB board path (gpubridge_usb), which this gpubridged was built "
                    "without; use \"sim\", \"auto\", \"fake\" or \"discard\"");
#endif
}

Result<std::string> check_backend(const DaemonConfig& cfg) {
  const std::string& name = cfg.backend;
  const bool board = is_board_backend(name);
  if (cfg.mirror && !board)
    return make_error("--mirror needs a board backend (a board profile name, emulated:BOARD or auto), not \"" + name +
                      "\": mirror mode compares a board with the simulator");
  const std::string mirrored = cfg.mirror ? ", mirrored by the simulator" : "";
  if (name == "sim") return simulator_available() ? Result<std::string>("the simulator") : make_simulator().error();
  if (name == "discard") return std::string("discard (accepts every command, scans out nothing)");
  if (name == "fake") return std::string("fake (test backend: registers, 1 MiB of memory, 64x48 frames)");
  if (name.starts_with("fake:")) {
    auto size = parse_fake_size(name);
    if (!size) return size.error();
    return "fake (test backend, " + std::to_string(size->first) + "x" + std::to_string(size->second) + " frames)";
  }
#ifdef GPUBRIDGE_HAVE_USB
  auto profiles = board_profiles_of(cfg, name);
  if (!profiles) return profiles.error();
  if (name == "auto") {
    const std::string first = "auto: the first of " + std::to_string(profiles->size()) + " board profiles in " +
                              (config_dir_of(cfg) / "boards").string() + " whose adapter is present";
    if (cfg.mirror) return first + mirrored + " (with --mirror the daemon does not start when none is present)";
    return first + ", else the simulator" + (cfg.reattach_interval_ms ? " until a board is plugged in" : "");
  }
  const auto& profile = profiles->front();
  return "board " + profile.name + " (" + std::string(usb::to_string(profile.chip)) +
         (name.starts_with(kEmulatedPrefix) ? ", emulated" : "") + ") from " + profile.file.string() + mirrored;
#else
  if (name == "auto") return std::string("auto: the simulator (this gpubridged has no USB board path)");
  return make_backend(name, cfg).error();
#endif
}

bool is_board_backend(const std::string& name) {
  return !(name == "sim" || name == "discard" || name == "fake" || name.starts_with("fake:"));
}

std::function<Result<std::unique_ptr<backends::Backend>>()> make_reattach_factory(const DaemonConfig& cfg) {
#ifdef GPUBRIDGE_HAVE_USB
  if (!is_board_backend(cfg.backend)) return {};
  const std::string name = cfg.backend;
  // A copy of the configuration: the factory runs later, on the device thread.
  return [name, cfg]() -> Result<std::unique_ptr<backends::Backend>> {
    if (name == "auto") {
      if (auto board = first_present_board(cfg)) return board;
      return make_error("auto: no board attached", backends::kDeviceGone);
    }
    return make_backend(name, cfg);
  };
#else
  (void)cfg;
  return {};
#endif
}

Result<std::shared_ptr<void>> watch_board_usb(const DaemonConfig& cfg, std::function<void()> on_event) {
  const std::string& name = cfg.backend;
  if (!is_board_backend(name) || name.starts_with(kEmulatedPrefix) || cfg.reattach_interval_ms == 0)
    return std::shared_ptr<void>();
#ifdef GPUBRIDGE_HAVE_USB
  auto profiles = board_profiles_of(cfg, name);
  if (!profiles) return profiles.error();
  std::vector<std::pair<std::uint16_t, std::uint16_t>> ids;
  for (const auto& p : *profiles) ids.emplace_back(p.vid, p.pid);
  if (ids.empty()) return std::shared_ptr<void>();
  auto monitor = usb::HotplugMonitor::start(ids, [on_event = std::move(on_event)](bool, std::uint16_t, std::uint16_t) { on_event(); });
  if (!monitor) return monitor.error();
  return std::shared_ptr<void>(std::move(*monitor));
#else
  (void)on_event;
  return std::shared_ptr<void>();
#endif
}

}  // namespace gpubridge::daemon
