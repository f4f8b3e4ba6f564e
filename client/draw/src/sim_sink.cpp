#include "gpubridge/draw/sim_sink.hpp"

namespace gpubridge::draw {

Result<std::unique_ptr<SimulatorSink>> SimulatorSink::create(const sim::DeviceOptions& options) {
  auto b = sim::SimBackend::create(options);
  if (!b) return b.error();
  std::unique_ptr<SimulatorSink> s(new SimulatorSink(std::move(*b)));
  s->backend_->set_scanout_callback([latest = s->latest_, count = s->count_](std::shared_ptr<const backends::ScanoutFrame> f) {
    *latest = std::move(f);
    ++*count;
  });
  return s;
}

}  // namespace gpubridge::draw
