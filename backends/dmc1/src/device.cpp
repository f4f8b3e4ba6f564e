#include "gpubridge/dmc1/device.hpp"

#include "column_buffers.hpp"
#include "column_renderer.hpp"
#include "command_fifo.hpp"
#include "dispatcher.hpp"
#include "gpubridge/dmc1/scanout.hpp"
#include "gpubridge/protocol/pixel.hpp"

namespace gpubridge::dmc1 {

struct Device::Impl {
  Impl(const DeviceOptions& o, std::shared_ptr<const TextureMemory> t, const Palette& p)
      : dispatcher(t), renderer(t, o.threads), scanout(p), timing(o.timing), screen(kFramePixels, 0) {
    fifo.clear(0);
  }

  // Runs the renderer over the FIFO; delivers the frame when the batch completed one.
  void drain() {
    if (fifo.empty()) return;
    renderer.run(fifo, buffers, scanout, screen.data());
    const bool frame_done = fifo.frame_complete;
    fifo.clear(dispatcher.draw_buffer());
    if (!frame_done) return;
    ++stats.frames;
    if (!callback) return;
    Frame f;
    f.number = frames_sent++;
    f.rgb565 = screen;  // a view: no copy per frame
    const auto& cycles = timing.frame_cycles();
    f.gpu_cycles = cycles.empty() ? 0 : cycles.back();
    callback(f);
  }

  Dispatcher dispatcher;
  ColumnRenderer renderer;
  Scanout scanout;
  TimingModel timing;
  CommandFifo fifo;
  ColumnBuffers buffers;
  std::vector<std::uint16_t> screen;
  DeviceStats stats;
  FrameCallback callback;
  std::uint32_t frames_sent = 0;
};

Result<std::unique_ptr<Device>> Device::create(const DeviceOptions& options, std::shared_ptr<const TextureMemory> textures,
                                               const Palette& palette) {
  if (options.threads < 1 || options.threads > 64)
    return make_error("DMC-1 threads " + std::to_string(options.threads) + ": expected 1..64");
  if (!textures) return make_error("DMC-1 device needs a texture memory (load one with load_texture_memory)");
  if (!(options.timing.clock_mhz > 0)) return make_error("DMC-1 timing: clock_mhz must be positive");
  return std::unique_ptr<Device>(new Device(std::make_unique<Impl>(options, std::move(textures), palette)));
}

Device::Device(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Device::~Device() = default;

void Device::submit(std::span<const std::uint64_t> words) {
  Impl& m = *impl_;
  for (const std::uint64_t w : words) {
    m.dispatcher.push(w, m.fifo, m.timing, m.stats);
    if (m.fifo.full()) m.drain();
  }
}

void Device::flush() { impl_->drain(); }

void Device::reset() {
  Impl& m = *impl_;
  m.fifo.clear(0);
  m.dispatcher.reset();
  m.buffers = {};
  m.timing.reset();
}

void Device::set_frame_callback(FrameCallback cb) { impl_->callback = std::move(cb); }
std::span<const std::uint16_t> Device::screen() const { return impl_->screen; }
unsigned Device::column() const { return impl_->dispatcher.column(); }
const DeviceStats& Device::stats() const { return impl_->stats; }
const TimingModel& Device::timing() const { return impl_->timing; }
std::uint8_t Device::picked_height() const { return impl_->dispatcher.registers().picked_height; }
unsigned Device::threads() const { return impl_->renderer.threads(); }

std::vector<std::uint8_t> frame_rows_rgb565(std::span<const std::uint16_t> column_major) {
  std::vector<std::uint8_t> out(kFramePixels * 2, 0);
  for (unsigned y = 0; y < kRows; ++y) {
    const unsigned row = kRows - 1 - y;
    std::uint8_t* line = out.data() + std::size_t{y} * kColumns * 2;
    for (unsigned x = 0; x < kColumns; ++x) {
      const std::size_t i = std::size_t{x} * kRows + row;
      const std::uint16_t v = i < column_major.size() ? column_major[i] : 0;
      line[2 * x] = static_cast<std::uint8_t>(v >> 8);
      line[2 * x + 1] = static_cast<std::uint8_t>(v);
    }
  }
  return out;
}

Image frame_image(std::span<const std::uint16_t> rgb565) {
  return image_from_device(protocol::PixelFormat::RGB565, kColumns, kRows, frame_rows_rgb565(rgb565));
}

}  // namespace gpubridge::dmc1
