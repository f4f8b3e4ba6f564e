#include "gpubridge/daemon/backend_factory.hpp"

#include <cstdio>

#include "gpubridge/daemon/test_backends.hpp"

#ifdef GPUBRIDGE_HAVE_SIM
#include "gpubridge/sim/sim_backend.hpp"
#endif

namespace gpubridge::daemon {

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
  (void)cfg;
  if (name == "sim") return make_simulator();
  if (name == "discard") return std::unique_ptr<backends::Backend>(std::make_unique<DiscardBackend>());
  if (name == "fake") return std::unique_ptr<backends::Backend>(std::make_unique<FakeScanoutBackend>());
  if (name.starts_with("fake:")) {  // fake:WxH, frames of that size (fan-out and memory tests)
    unsigned w = 0, h = 0;
    char x = 0;
    if (std::sscanf(name.c_str() + 5, "%u%c%u", &w, &x, &h) != 3 || x != 'x' || w < 1 || h < 1 ||
        w > protocol::kMaxFramebufferDim || h > protocol::kMaxFramebufferDim)
      return make_error("backend \"" + name + "\": expected fake:WIDTHxHEIGHT with sizes 1..1024");
    return std::unique_ptr<backends::Backend>(std::make_unique<FakeScanoutBackend>(w, h));
  }
  if (name == "auto") {
    // Board detection arrives with the USB board path; until it is linked in, auto = simulator.
    return make_simulator();
  }
  return make_error("backend \"" + name +
                    "\": board backends need the USB board path (gpubridge_usb), which this gpubridged was built "
                    "without; use \"sim\", \"auto\", \"fake\" or \"discard\"");
}

}  // namespace gpubridge::daemon
