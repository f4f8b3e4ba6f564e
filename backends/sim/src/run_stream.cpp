#include "gpubridge/sim/run_stream.hpp"

#include <algorithm>
#include <string>
#include <variant>

namespace gpubridge::sim {

Result<void> run_stream(Device& device, const protocol::CommandStream& stream) {
  std::size_t n = 0;
  for (const auto& tc : stream.commands) {
    ++n;
    const auto& c = tc.command;
    if (const auto* f = std::get_if<protocol::FramesCmd>(&c)) {
      device.write(f->view());
    } else if (const auto* u = std::get_if<protocol::UploadCmd>(&c)) {
      device.drain();
      auto mem = device.memory();
      if (std::uint64_t{u->address} + u->data.size() > mem.size())
        return make_error("command " + std::to_string(n) + ": upload of " + std::to_string(u->data.size()) +
                          " bytes at address " + std::to_string(u->address) + " reaches beyond the simulator's " +
                          std::to_string(mem.size()) + " bytes of video memory; raise the VRAM size or move it");
      std::copy(u->data.begin(), u->data.end(), mem.begin() + u->address);
    } else if (std::holds_alternative<protocol::FenceCmd>(c)) {
      device.drain();
    } else if (const auto* r = std::get_if<protocol::ReadRegCmd>(&c)) {
      device.read(r->index);
    } else if (const auto* rb = std::get_if<protocol::ReadbackCmd>(&c)) {
      device.drain();
      if (std::uint64_t{rb->address} + rb->length > device.memory().size())
        return make_error("command " + std::to_string(n) + ": readback of " + std::to_string(rb->length) +
                          " bytes at address " + std::to_string(rb->address) + " reaches beyond video memory");
    }
  }
  device.drain();
  return {};
}

}  // namespace gpubridge::sim
