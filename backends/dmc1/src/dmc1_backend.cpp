#include "gpubridge/dmc1/dmc1_backend.hpp"

#include <chrono>

#include "gpubridge/protocol/crc32.hpp"

namespace gpubridge::dmc1 {
namespace {

// Words per simulator call: a cancelled batch stops between slices (the board's link stops at a word).
constexpr std::size_t kSubmitSlice = 4096;

}  // namespace

Result<std::unique_ptr<Dmc1Backend>> Dmc1Backend::create(std::shared_ptr<const TextureMemory> textures,
                                                         const Palette& palette, const Dmc1BackendOptions& options,
                                                         std::unique_ptr<SerialLink> link) {
  DeviceOptions d;
  d.threads = options.threads;
  auto device = Device::create(d, std::move(textures), palette);
  if (!device) return device.error();
  std::unique_ptr<Dmc1Backend> b(new Dmc1Backend(std::move(*device), std::move(link), options));
  b->device_->set_frame_callback([p = b.get()](const Frame& f) { p->scan_out(f); });
  return b;
}

Dmc1Backend::Dmc1Backend(std::unique_ptr<Device> device, std::unique_ptr<SerialLink> link, Dmc1BackendOptions options)
    : device_(std::move(device)), link_(std::move(link)), options_(std::move(options)) {}

Dmc1Backend::~Dmc1Backend() = default;

backends::DeviceInfo Dmc1Backend::info() const {
  backends::DeviceInfo d;
  d.kind = protocol::DeviceKind::Dmc1;
  d.backend = link_ ? "board" : "sim";
  d.board = options_.board;
  if (link_) d.bridge = "uart " + link_->path() + " @ " + std::to_string(link_->baud()) + " baud";
  d.max_width = kColumns;
  d.max_height = kRows;
  if (link_)
    d.frames_note = "the simulator's frames, computed from the same command words: the board sends none back";
  return d;
}

Error Dmc1Backend::not_this_kind(const char* what) const {
  return make_error(std::string(what) + " is a spigpu operation; a DMC-1 takes command words (DMC1_WORDS)",
                    backends::kBadRequest);
}

Result<void> Dmc1Backend::write_frames(protocol::FrameView) { return not_this_kind("WRITE_FRAMES"); }
Result<std::uint64_t> Dmc1Backend::read_register(std::uint8_t) { return not_this_kind("READ_REG"); }
Result<void> Dmc1Backend::upload(std::uint32_t, std::span<const std::uint8_t>) { return not_this_kind("UPLOAD"); }
Result<std::vector<std::uint8_t>> Dmc1Backend::readback(std::uint32_t, std::uint32_t) { return not_this_kind("READBACK"); }

Result<void> Dmc1Backend::write_dmc1_words(std::span<const std::uint64_t> words) {
  for (std::size_t at = 0; at < words.size(); at += kSubmitSlice) {
    if (cancel_ && cancel_->load(std::memory_order_relaxed))
      return make_error("cancelled after " + std::to_string(at) + " command words", backends::kCancelled);
    const auto slice = words.subspan(at, std::min(kSubmitSlice, words.size() - at));
    // The board first: the simulator's frame stands for what the board shows, so it must not run
    // ahead of words the board never got.
    if (link_) {
      if (auto r = link_->send(slice); !r) {
        if (r.error().code == kSerialCancelled) return make_error(r.error().message, backends::kCancelled);
        return make_error("board " + options_.board + " (" + link_->path() + "): " + r.error().message,
                          backends::kDeviceGone);
      }
    }
    device_->submit(slice);
  }
  return {};
}

Result<void> Dmc1Backend::flush() {
  device_->flush();
  if (link_) {
    if (auto r = link_->drain(); !r)
      return make_error("board " + options_.board + " (" + link_->path() + "): " + r.error().message, backends::kDeviceGone);
  }
  return {};
}

Result<void> Dmc1Backend::reset() {
  device_->reset();
  return {};
}

void Dmc1Backend::set_cancel_flag(const std::atomic<bool>* flag) {
  cancel_ = flag;
  if (link_) link_->set_cancel_flag(flag);
}

void Dmc1Backend::scan_out(const Frame& f) {
  if (!callback_) return;
  auto frame = std::make_shared<backends::ScanoutFrame>();
  frame->number = f.number;
  frame->width = kColumns;
  frame->height = kRows;
  frame->format = protocol::PixelFormat::RGB565;
  frame->pixels = frame_rows_rgb565(f.rgb565);
  frame->crc = protocol::crc32(frame->pixels);
  frame->swap_time = std::chrono::steady_clock::now();
  callback_(std::move(frame));
}

}  // namespace gpubridge::dmc1
