#pragma once
// What the parts of the board backend share (board_backend.cpp: attach and the Backend calls;
// board_link.cpp: the SPI link, flow control and link integrity; board_memory.cpp: upload and
// readback through MEM_ADDR/MEM_DATA; board_scanout.cpp: frames after a display swap).
#include <cstdint>
#include <vector>

#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::usb::board {

using protocol::Frame;
using protocol::Reg;
using protocol::index_of;
using protocol::kFrameBytes;

inline constexpr std::size_t kGroupFrames = 32;  // queued frames per BUSY check / link group
// STATUS bits the host waits on (docs/protocol.md, STATUS).
inline constexpr std::uint64_t kStatusBusy = 1ull << 16, kStatusMemReady = 1ull << 18, kStatusSwapPending = 1ull << 19,
                               kStatusLinkPending = 1ull << 20, kStatusLevelMask = 0xFFFF;
inline constexpr std::uint64_t kLinkDiscarding = 1ull << 24;  // LINK_STATUS.DISCARDING

inline std::uint16_t groups_ok_of(std::uint64_t link_status) { return static_cast<std::uint16_t>(link_status >> 32); }
inline void append_frame(std::vector<std::uint8_t>& out, const protocol::Frame& f) { protocol::append(out, f); }
// The 64-bit value of the k-th frame of a MISO capture (after its status byte).
inline std::uint64_t frame_value(const std::vector<std::uint8_t>& miso, std::size_t k) {
  std::uint64_t v = 0;
  for (std::size_t b = 1; b <= 8; ++b) v = v << 8 | miso[k * protocol::kFrameBytes + b];
  return v;
}

}  // namespace gpubridge::usb::board
