#pragma once
// Builds the daemon's backend from its name. The kinds are one table (kKinds in
// backend_factory.cpp, the only code that knows the names): "sim" (the simulator, default),
// "discard" and "fake[:WxH]" (test_backends.hpp), "auto" (the first board profile whose real
// bridge opens, else the simulator), "emulated:PROFILE[?presence=PATH]" (that board's bridge-chip
// model + simulator, same driver code; with presence the emulated adapter is plugged in only while
// PATH exists), "rtl:PROFILE" (that board's bridge-chip model in front of the board's Verilated
// gateware, docs/gateware.md), and any other name: a board profile name or .json path (the real board).
#include <functional>
#include <memory>
#include <string>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/daemon/config.hpp"

namespace gpubridge::daemon {

Result<std::unique_ptr<backends::Backend>> make_backend(const std::string& name, const DaemonConfig& cfg);
// What cfg.backend (with cfg.mirror) would serve, checked without opening any device: the name's
// syntax, the board profile it names (found and valid), every profile for "auto". A one-line
// description, or the error make_backend would give for the same reason (`gpubridged --check-config`).
Result<std::string> check_backend(const DaemonConfig& cfg);
// The simulator with cfg's accuracy settings (backend sim, auto without a board, the fallback when
// a board disappears).
Result<std::unique_ptr<backends::Backend>> make_simulator(const DaemonConfig& cfg);
// The backend names in --help form: "sim | auto | emulated:BOARD[?presence=PATH] | ...".
std::string backend_syntax();
// True for backends that name a board ("auto", a profile, "emulated:PROFILE"): those can
// disappear and come back, and can be mirrored.
bool is_board_backend(const std::string& name);
// What replaces cfg's backend when it disappears: the simulator for boards with fallback_to_sim,
// else nothing (empty).
std::function<Result<std::unique_ptr<backends::Backend>>()> fallback_factory(const DaemonConfig& cfg);
// Re-opens the configured board after it disappeared (the hub calls it on the device thread until
// it succeeds); "auto" looks for any present board but never settles for the simulator. Empty
// for backends that cannot disappear (sim, fake, discard).
std::function<Result<std::unique_ptr<backends::Backend>>()> make_reattach_factory(const DaemonConfig& cfg);
// libusb hot-plug notifications for the USB ids of cfg's real board(s) (the named profile, or every
// profile for "auto"); `on_event` runs on the watcher's thread for each plug or unplug (Hub::
// hotplug_event). Holding the result keeps watching. nullptr when there is nothing to watch
// (simulator, test and emulated backends, re-attach disabled); an error when notifications are
// unavailable (the daemon then relies on polling).
Result<std::shared_ptr<void>> watch_board_usb(const DaemonConfig& cfg, std::function<void()> on_event);

}  // namespace gpubridge::daemon
