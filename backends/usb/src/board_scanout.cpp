// Board backend, scanout: after a display swap, the frame the board shows: FRAME_CRC (read twice)
// and, with scanout "readback", the pixels, re-read until they match the CRC.
#include "gpubridge/usb/board_backend.hpp"

#include <chrono>

#include <fmt/format.h>

#include "board_parts.hpp"
#include "gpubridge/protocol/crc32.hpp"

namespace gpubridge::usb {

using namespace board;

constexpr unsigned kScanoutAttempts = 3;

Result<void> BoardBackend::emit_scanout() {
  if (auto r = poll_status(kStatusBusy | kStatusLinkPending | kStatusSwapPending | kStatusLevelMask, 0, "the display swap"); !r)
    return r.error();
  // FB_FORMAT and FB_DISPLAY as the device validated them (a format or size the design lacks was
  // replaced), not as they were written.
  // Each read twice; a pair that disagrees is read again (a bit error on MOSI turns a read into a
  // read of another register, one on MISO garbles the value; neither is covered by a link group),
  // HOST_TAG rides in the same transfer: a board reset since the swap leaves pairs that agree on
  // reset values, which are no frame.
  const std::uint8_t idx[] = {index_of(Reg::FRAME_CRC),  index_of(Reg::FRAME_CRC),  index_of(Reg::FB_FORMAT), index_of(Reg::FB_FORMAT),
                              index_of(Reg::FB_DISPLAY), index_of(Reg::FB_DISPLAY), index_of(Reg::HOST_TAG)};
  std::vector<std::uint64_t> v;
  for (unsigned attempt = 0;; ++attempt) {
    auto r = read_frames(idx);
    if (!r) return r.error();
    v = std::move(*r);
    if (v[0] == v[1] && v[2] == v[3] && v[4] == v[5] && v[6] == tag_) break;
    if (auto t = check_host_tag(); !t) return t.error();
    if (attempt + 1 >= kScanoutAttempts)
      return make_error("board '" + profile_.name + "': FRAME_CRC, FB_FORMAT or FB_DISPLAY reads disagree after " +
                            std::to_string(kScanoutAttempts) + " attempts (SPI bit errors); lower bridge.spi_clock_hz",
                        backends::kDeviceProtocol);
  }
  fb_format_ = v[2];
  fb_display_ = v[4];
  auto frame = std::make_shared<backends::ScanoutFrame>();
  frame->crc = static_cast<std::uint32_t>(v[0]);
  frame->number = ++frame_number_;
  frame->width = fb_format_ & 0x7FF;
  frame->height = (fb_format_ >> 16) & 0x7FF;
  frame->format = static_cast<protocol::PixelFormat>((fb_format_ >> 32) & 3);
  frame->swap_time = std::chrono::steady_clock::now();
  if (profile_.scanout == ScanoutMode::Readback) {
    const std::uint64_t bytes = std::uint64_t{frame->width} * frame->height * protocol::bytes_per_pixel(frame->format);
    const std::uint32_t base = static_cast<std::uint32_t>(fb_display_ & 0xFFFFFFF0u);
    if (bytes == 0 || base + bytes > vram_bytes_)
      return make_error("board '" + profile_.name + "': display buffer at 0x" + fmt::format("{:X}", base) + " of " +
                            std::to_string(bytes) + " bytes does not fit video memory (" + std::to_string(vram_bytes_) + " bytes)",
                        backends::kBadRequest);
    for (unsigned attempt = 0;; ++attempt) {
      auto px = readback_locked(base, static_cast<std::uint32_t>(bytes), /*verify=*/false);  // FRAME_CRC checks it
      if (!px) return px.error();
      if (protocol::crc32(*px) == frame->crc) {
        frame->pixels = std::move(*px);
        break;
      }
      if (attempt + 1 >= kScanoutAttempts)
        return make_error("board '" + profile_.name + "': scanout readback does not match FRAME_CRC after " +
                              std::to_string(kScanoutAttempts) + " attempts (SPI bit errors); lower bridge.spi_clock_hz",
                          backends::kDeviceProtocol);
    }
  }
  pending_frames_.push_back(std::move(frame));
  return {};
}

}  // namespace gpubridge::usb
