#include "gpubridge/daemon/test_backends.hpp"

#include <algorithm>

#include "gpubridge/protocol/crc32.hpp"

namespace gpubridge::daemon {
namespace {

Result<void> check_writes(protocol::FrameView frames) {
  if (const std::size_t i = protocol::first_read_frame(frames); i < frames.size())
    return make_error("frame " + std::to_string(i) + " of the batch is a read frame", backends::kBadRequest);
  return {};
}

Result<void> check_range(std::uint32_t address, std::uint64_t length, std::uint64_t size) {
  if (std::uint64_t{address} > size || length > size - address)
    return make_error("memory range 0x" + std::to_string(address) + "+" + std::to_string(length) + " is beyond the " +
                          std::to_string(size) + "-byte memory",
                      backends::kBadRequest);
  return {};
}

}  // namespace

backends::DeviceInfo DiscardBackend::info() const {
  backends::DeviceInfo d;
  d.backend = "discard";
  d.vram_bytes = 0;
  return d;
}

Result<void> DiscardBackend::write_frames(protocol::FrameView frames) {
  if (auto r = check_writes(frames); !r) return r;
  frames_.fetch_add(frames.size(), std::memory_order_relaxed);
  return {};
}
Result<std::uint64_t> DiscardBackend::read_register(std::uint8_t) { return std::uint64_t{0}; }
Result<void> DiscardBackend::upload(std::uint32_t, std::span<const std::uint8_t>) { return {}; }
Result<std::vector<std::uint8_t>> DiscardBackend::readback(std::uint32_t, std::uint32_t length) {
  if (length > (64u << 20)) return make_error("readback longer than 64 MiB", backends::kBadRequest);
  return std::vector<std::uint8_t>(length, 0);
}

FakeScanoutBackend::FakeScanoutBackend(unsigned width, unsigned height, std::size_t memory_bytes)
    : width_(width), height_(height), memory_(memory_bytes, 0) {
  (void)reset();
}

backends::DeviceInfo FakeScanoutBackend::info() const {
  backends::DeviceInfo d;
  d.backend = "fake";
  d.max_width = width_;
  d.max_height = height_;
  d.vram_bytes = memory_.size();
  d.id = regs_[protocol::index_of(protocol::Reg::ID)];  // the constants its registers hold
  d.caps = regs_[protocol::index_of(protocol::Reg::CAPS)];
  d.caps2 = regs_[protocol::index_of(protocol::Reg::CAPS2)];
  return d;
}

Result<void> FakeScanoutBackend::reset() {
  for (const auto& r : protocol::register_table()) regs_[r.index] = r.reset;
  return {};
}

Result<void> FakeScanoutBackend::write_frames(protocol::FrameView frames) {
  if (auto r = check_writes(frames); !r) return r;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto f = frames[i];
    regs_[f.index] = f.data;
    if (f.index == protocol::index_of(protocol::Reg::FB_DISPLAY)) scan_out();
  }
  return {};
}

void FakeScanoutBackend::scan_out() {
  auto frame = std::make_shared<backends::ScanoutFrame>();
  frame->number = ++frame_number_;
  frame->width = width_;
  frame->height = height_;
  frame->format = protocol::PixelFormat::RGBA8888;
  frame->pixels.resize(std::size_t{width_} * height_ * 4);
  const std::uint64_t color = regs_[protocol::index_of(protocol::Reg::CLEAR_COLOR)];
  for (std::size_t p = 0; p < frame->pixels.size(); p += 4) {
    frame->pixels[p + 0] = static_cast<std::uint8_t>(color >> 24);
    frame->pixels[p + 1] = static_cast<std::uint8_t>(color >> 16);
    frame->pixels[p + 2] = static_cast<std::uint8_t>(color >> 8);
    frame->pixels[p + 3] = static_cast<std::uint8_t>(frame->number);
  }
  frame->crc = protocol::crc32(frame->pixels);
  frame->swap_time = std::chrono::steady_clock::now();
  if (callback_) callback_(std::move(frame));
}

Result<std::uint64_t> FakeScanoutBackend::read_register(std::uint8_t index) {
  if (index >= protocol::kRegisterCount) return make_error("register index out of range", backends::kBadRequest);
  return regs_[index];
}

Result<void> FakeScanoutBackend::upload(std::uint32_t address, std::span<const std::uint8_t> bytes) {
  if (auto r = check_range(address, bytes.size(), memory_.size()); !r) return r;
  std::copy(bytes.begin(), bytes.end(), memory_.begin() + address);
  return {};
}

Result<std::vector<std::uint8_t>> FakeScanoutBackend::readback(std::uint32_t address, std::uint32_t length) {
  if (auto r = check_range(address, length, memory_.size()); !r) return r.error();
  return std::vector<std::uint8_t>(memory_.begin() + address, memory_.begin() + address + length);
}

}  // namespace gpubridge::daemon
