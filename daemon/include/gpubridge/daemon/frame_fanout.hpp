#pragma once
// FrameFanout: one scanned-out swap as the FRAME messages subscribers ask for. Each (picture,
// format) is encoded the first time a subscriber is about to be sent it and then shared by every
// subscriber of that swap; a swap nobody is sent is never converted. Network thread only.
#include <cstdint>
#include <memory>
#include <vector>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::daemon {

class FrameFanout {
 public:
  using Buffer = std::shared_ptr<const std::vector<std::uint8_t>>;

  explicit FrameFanout(std::shared_ptr<const backends::ScanoutFrame> frame) : frame_(std::move(frame)) {}
  // The complete FRAME message for `source` in `format`; null when this swap has no such picture
  // (a CRC-only board has no board or diff pixels; without mirror mode there is no sim or diff).
  Buffer message(protocol::FrameSource source, protocol::FrameFormat format);
  Buffer message(protocol::FrameFormat format) { return message(protocol::FrameSource::Board, format); }
  const backends::ScanoutFrame& frame() const { return *frame_; }

 private:
  std::shared_ptr<const backends::ScanoutFrame> picture(protocol::FrameSource source);
  std::shared_ptr<const backends::ScanoutFrame> frame_;
  std::shared_ptr<const backends::ScanoutFrame> diff_;  // computed on first use
  bool diff_done_ = false;
  Buffer encoded_[3][4];  // [source][format]
};

}  // namespace gpubridge::daemon
