#include "gpubridge/examples/prediction.hpp"

#include <algorithm>
#include <cmath>

#include "gpubridge/draw/sim_sink.hpp"

namespace gpubridge::examples {
namespace {

// The simulator takes uploads straight into its memory; a board receives them as register
// frames (board_backend.cpp: MEM_ADDR, then one MEM_DATA per 8 bytes). This sink counts those
// frames so a frame that re-uploads a texture (cubes' label) pays for it on the link.
class UploadCountingSink final : public draw::CommandSink {
 public:
  explicit UploadCountingSink(draw::CommandSink& inner) : inner_(inner) {}
  Result<void> write_frames(protocol::FrameView frames) override { return inner_.write_frames(frames); }
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override {
    if (!bytes.empty()) {
      const std::uint64_t data = (bytes.size() + 7) / 8;
      frames_ += 1 + data;
      mem_data_ += data;
    }
    return inner_.upload(address, bytes);
  }
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override {
    return inner_.readback(address, length);
  }
  Result<void> flush() override { return inner_.flush(); }
  backends::DeviceInfo device() const override { return inner_.device(); }

  std::uint64_t frames() const { return frames_; }
  std::uint64_t mem_data() const { return mem_data_; }

 private:
  draw::CommandSink& inner_;
  std::uint64_t frames_ = 0, mem_data_ = 0;
};

}  // namespace

Result<FramePrediction> predict_frame(Example& ex, const DeviceCaps& device, const BoardLink& board,
                                      const FitRequest& request) {
  FramePrediction p;
  auto fitted = configure(ex, device, request);
  if (!fitted) return fitted.error();
  p.fit = *fitted;
  auto options = device.simulator_options();
  options.sdram_rows = true;  // the row and footprint terms of the estimate
  auto sink = draw::SimulatorSink::create(options);
  if (!sink) return sink.error();
  UploadCountingSink counting(**sink);
  auto ctx = draw::Context::create(counting, ex.options());
  if (!ctx) return make_error(ex.info().name + ": " + ctx.error().message);
  const sim::Device& d = (*sink)->backend().device();
  sim::DeviceStats before;
  std::uint64_t upload_frames = 0, upload_mem_data = 0;
  if (auto r = run_frames(ex, *ctx, 0, kGoldenFrame + 1, [&](unsigned n) -> Result<void> {
        if (n + 1 == kGoldenFrame) {
          before = d.stats();
          upload_frames = counting.frames();
          upload_mem_data = counting.mem_data();
        }
        return {};
      });
      !r)
    return r.error();
  p.work = sim::stats_difference(d.stats(), before);
  p.work.frames_received += counting.frames() - upload_frames;
  p.work.mem_data_writes += counting.mem_data() - upload_mem_data;

  sim::BoardTiming timing;
  timing.name = board.name;
  timing.clock_mhz = board.clock_mhz;
  timing.spi_clock_mhz = board.spi_clock_mhz;
  const unsigned bpp = protocol::bytes_per_pixel(p.fit.context.format);
  p.estimate = sim::estimate_timing(p.work, timing, bpp, p.fit.context.depth_buffer);
  if (board.readback) {
    // MEM_DATA reads: one 72-bit frame per 8 bytes, in bursts like the writes.
    p.readback_ms = sim::spi_link_ms(std::ceil(double(p.fit.context.width) * p.fit.context.height * bpp / 8), timing);
  }
  p.fps = p.estimate.fps;
  const double viewed_ms = std::max(p.estimate.board_ms, p.estimate.spi_ms + p.readback_ms);
  p.fps_with_readback = viewed_ms > 0 ? 1000 / viewed_ms : 0;
  return p;
}

}  // namespace gpubridge::examples
