#include "scanout.hpp"

#include <chrono>
#include <vector>

#include "gpubridge/protocol/crc32.hpp"

namespace gpubridge::sim {

std::shared_ptr<backends::ScanoutFrame> Scanout::latch(const VideoMemory& mem, std::uint32_t address, unsigned width,
                                                       unsigned height, protocol::PixelFormat format, bool want_pixels,
                                                       std::uint16_t& errors) {
  ++frames_;
  crc_frame_ = static_cast<std::uint16_t>(frames_);
  const std::uint64_t length = std::uint64_t{width} * height * protocol::bytes_per_pixel(format);
  std::shared_ptr<backends::ScanoutFrame> frame;
  std::span<const std::uint8_t> bytes;
  std::vector<std::uint8_t> copy;
  const bool inside = mem.contains(address, length);
  if (!inside) errors |= protocol::ERR_MEM_RANGE;
  if (want_pixels || !inside) {
    copy.resize(length);
    mem.read(address, copy.data(), copy.size());
    bytes = copy;
  } else {
    bytes = mem.span().subspan(address, length);
  }
  crc_ = protocol::crc32(bytes);
  if (want_pixels) {
    frame = std::make_shared<backends::ScanoutFrame>();
    frame->number = frames_;
    frame->width = width;
    frame->height = height;
    frame->format = format;
    frame->pixels = std::move(copy);
    frame->crc = crc_;
    frame->swap_time = std::chrono::steady_clock::now();
  }
  return frame;
}

}  // namespace gpubridge::sim
