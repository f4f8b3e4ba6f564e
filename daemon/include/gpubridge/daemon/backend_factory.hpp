#pragma once
// Builds the daemon's backend from its name: "sim" (the simulator, default), "discard" and
// "fake" (test_backends.hpp), "auto" (the first board profile whose real bridge opens, else the
// simulator), a board profile name or .json path (the real board), or "emulated:PROFILE" (that
// board's bridge-chip model + simulator, same driver code). Boards need the USB board path,
// linked in when gpubridge_usb is built.
#include <memory>
#include <string>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/daemon/config.hpp"

namespace gpubridge::daemon {

Result<std::unique_ptr<backends::Backend>> make_backend(const std::string& name, const DaemonConfig& cfg);
// The simulator with default options (fallback when a board disappears).
Result<std::unique_ptr<backends::Backend>> make_simulator();
bool simulator_available();

}  // namespace gpubridge::daemon
