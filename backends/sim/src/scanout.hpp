#pragma once
// Scanout (docs/protocol.md section 12): at the vertical sync after an FB_DISPLAY write the display
// address and FB_FORMAT are latched, the frame counter advances and FRAME_CRC is computed over the
// latched buffer's bytes (bytes beyond VRAM count as 0). The untimed simulator syncs at once.
#include <cstdint>
#include <memory>

#include "gpubridge/backends/backend.hpp"
#include "video_memory.hpp"

namespace gpubridge::sim {

class Scanout {
 public:
  // Latches one frame. Returns the frame's pixels only when want_pixels (a callback listens);
  // sets ERR_MEM_RANGE in errors when part of the buffer lies beyond VRAM.
  std::shared_ptr<backends::ScanoutFrame> latch(const VideoMemory& mem, std::uint32_t address, unsigned width,
                                                unsigned height, protocol::PixelFormat format, bool want_pixels,
                                                std::uint16_t& errors);
  std::uint64_t frame_crc_register() const { return (std::uint64_t{crc_frame_} << 32) | crc_; }
  std::uint16_t frame_count() const { return static_cast<std::uint16_t>(frames_); }
  void reset() { *this = Scanout{}; }

 private:
  std::uint32_t frames_ = 0;  // full counter (STATUS.FRAME_COUNT is the low 16 bits)
  std::uint16_t crc_frame_ = 0;
  std::uint32_t crc_ = 0;
};

}  // namespace gpubridge::sim
