#include "gpubridge/sim/sim_backend.hpp"

#include <algorithm>
#include <string>

namespace gpubridge::sim {

Result<std::unique_ptr<SimBackend>> SimBackend::create(const DeviceOptions& options) {
  auto device = Device::create(options);
  if (!device) return device.error();
  return std::unique_ptr<SimBackend>(new SimBackend(std::move(device.value())));
}

backends::DeviceInfo SimBackend::info() const {
  backends::DeviceInfo i;
  i.backend = "sim";
  const DeviceOptions& o = device_->options();
  i.max_width = o.max_width;
  i.max_height = o.max_height;
  i.vram_bytes = o.vram_bytes;
  i.id = device_->id();
  i.caps = device_->caps();
  i.caps2 = device_->caps2();
  i.accuracy = accuracy_mode(o.accuracy);
  return i;
}

Result<void> SimBackend::write_frames(protocol::FrameView frames) {
  if (frames.bytes.size() % protocol::kFrameBytes != 0)
    return make_error("write_frames: " + std::to_string(frames.bytes.size()) + " bytes is not a whole number of " +
                          "9-byte frames",
                      backends::kBadRequest);
  if (const std::size_t i = protocol::first_read_frame(frames); i < frames.size())
    return make_error("write_frames: frame " + std::to_string(i) + " is a read frame; use read_register",
                      backends::kBadRequest);
  if (!cancel_) {
    device_->write(frames);
    return {};
  }
  // Executing frame by frame in slices changes nothing on the device; between slices the daemon
  // can stop a batch that would run for minutes (shutdown, client gone).
  const std::size_t slice = kCancelCheckFrames * protocol::kFrameBytes;
  for (std::size_t at = 0; at < frames.bytes.size(); at += slice) {
    if (cancel_->load(std::memory_order_relaxed))
      return make_error("write_frames: cancelled after " + std::to_string(at / protocol::kFrameBytes) + " of " +
                            std::to_string(frames.size()) + " frames",
                        backends::kCancelled);
    device_->write(protocol::FrameView{frames.bytes.subspan(at, std::min(slice, frames.bytes.size() - at))});
  }
  return {};
}

Result<std::uint64_t> SimBackend::read_register(std::uint8_t index) {
  if (index > 0x7F)
    return make_error("read_register: index " + std::to_string(index) + " is beyond 0x7F", backends::kBadRequest);
  return device_->read(index);
}

Result<void> SimBackend::upload(std::uint32_t address, std::span<const std::uint8_t> bytes) {
  device_->drain();
  auto mem = device_->memory();
  if (std::uint64_t{address} + bytes.size() > mem.size())
    return make_error("upload of " + std::to_string(bytes.size()) + " bytes at 0x" + std::to_string(address) +
                          " reaches beyond video memory (" + std::to_string(mem.size()) + " bytes)",
                      backends::kBadRequest);
  std::copy(bytes.begin(), bytes.end(), mem.begin() + address);
  return {};
}

Result<std::vector<std::uint8_t>> SimBackend::readback(std::uint32_t address, std::uint32_t length) {
  device_->drain();
  auto mem = device_->memory();
  if (std::uint64_t{address} + length > mem.size())
    return make_error("readback of " + std::to_string(length) + " bytes at " + std::to_string(address) +
                          " reaches beyond video memory (" + std::to_string(mem.size()) + " bytes)",
                      backends::kBadRequest);
  return std::vector<std::uint8_t>(mem.begin() + address, mem.begin() + address + length);
}

Result<void> SimBackend::flush() {
  device_->drain();
  (void)device_->memory();  // completes batched triangles
  return {};
}

Result<void> SimBackend::reset() {
  device_->write(protocol::write_frame(protocol::Reg::RESET, protocol::kResetMagic));
  return {};
}

void SimBackend::set_scanout_callback(backends::ScanoutCallback cb) { device_->set_scanout_callback(std::move(cb)); }

}  // namespace gpubridge::sim
