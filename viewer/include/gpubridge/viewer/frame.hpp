#pragma once
// One scanned-out frame as the viewer holds it: the device's own bytes (rows packed, big-endian
// device words) plus the metadata of the FRAME message it came in.
#include <cstdint>
#include <string>
#include <vector>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/messages.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::viewer {

// The viewer shows frames up to this size; larger FRAME messages are refused before any copy.
inline constexpr unsigned kMaxFrameDim = 1024;

struct Frame {
  std::uint32_t number = 0;  // the daemon's frame number
  unsigned width = 0, height = 0;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  std::uint32_t crc = 0;      // CRC-32 the daemon computed over the frame bytes
  std::uint64_t swap_ns = 0;  // CLOCK_MONOTONIC of the swap (daemon side; same machine -> comparable)
  std::vector<std::uint8_t> pixels;
  protocol::FrameSource source = protocol::FrameSource::Board;  // mirror mode: board, simulator or diff
};

// Empty when the frame's size, format and byte count are consistent and within kMaxFrameDim;
// otherwise what is wrong ("frame 12: 2048x16 is larger than 1024x1024").
std::string frame_problem(const Frame& f);

// Expands the device bytes to RGBA8888 (bit replication, docs/protocol.md "Pixel formats").
// Refuses inconsistent frames (see frame_problem).
Result<Image> frame_to_image(const Frame& f);

// True when the frame's bytes hash to the CRC the daemon sent with them.
bool crc_matches(const Frame& f);

// "640x480 RGBA8888"
std::string describe_size(const Frame& f);

}  // namespace gpubridge::viewer
