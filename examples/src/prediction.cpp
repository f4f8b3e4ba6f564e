#include "gpubridge/examples/prediction.hpp"

#include <algorithm>
#include <cmath>

#include "gpubridge/draw/sim_sink.hpp"

namespace gpubridge::examples {

Result<FramePrediction> predict_frame(Example& ex, const DeviceCaps& device, const BoardLink& board,
                                      const FitRequest& request) {
  FramePrediction p;
  auto fitted = configure(ex, device, request);
  if (!fitted) return fitted.error();
  p.fit = *fitted;
  auto sink = draw::SimulatorSink::create(device.simulator_options());
  if (!sink) return sink.error();
  auto ctx = draw::Context::create(**sink, ex.options());
  if (!ctx) return make_error(ex.info().name + ": " + ctx.error().message);
  const sim::Device& d = (*sink)->backend().device();
  sim::DeviceStats before;
  if (auto r = run_frames(ex, *ctx, 0, kGoldenFrame + 1, [&](unsigned n) -> Result<void> {
        if (n + 1 == kGoldenFrame) before = d.stats();
        return {};
      });
      !r)
    return r.error();
  p.work = sim::stats_difference(d.stats(), before);

  sim::BoardTiming timing;
  timing.name = board.name;
  timing.clock_mhz = board.clock_mhz;
  timing.spi_clock_mhz = board.spi_clock_mhz;
  const unsigned bpp = protocol::bytes_per_pixel(p.fit.context.format);
  p.estimate = sim::estimate_timing(p.work, timing, bpp, p.fit.context.depth_buffer);
  if (board.readback) {
    // MEM_DATA reads: one 72-bit frame per 8 bytes, in bursts like the writes.
    const double frames = std::ceil(double(p.fit.context.width) * p.fit.context.height * bpp / 8);
    p.readback_ms = frames * 72 / (timing.spi_clock_mhz * 1e3) +
                    std::ceil(frames / std::max(1u, timing.frames_per_burst)) * timing.cs_gap_us / 1e3;
  }
  p.fps = p.estimate.fps;
  const double viewed_ms = std::max(p.estimate.board_ms, p.estimate.spi_ms + p.readback_ms);
  p.fps_with_readback = viewed_ms > 0 ? 1000 / viewed_ms : 0;
  return p;
}

}  // namespace gpubridge::examples
