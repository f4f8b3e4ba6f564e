#pragma once
// The 72-bit SPI frame: [71] R/W̄ (1 = read), [70:64] register index, [63:0] data, sent MSB first
// as 9 bytes: byte 0 = R/W̄<<7 | index, bytes 1..8 = data big-endian.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::protocol {

inline constexpr std::size_t kFrameBytes = 9;

struct Frame {
  bool read = false;
  std::uint8_t index = 0;  // 0..127
  std::uint64_t data = 0;

  friend bool operator==(const Frame&, const Frame&) = default;
};

constexpr Frame write_frame(Reg r, std::uint64_t data) { return Frame{false, index_of(r), data}; }
constexpr Frame read_frame(Reg r) { return Frame{true, index_of(r), 0}; }

constexpr std::array<std::uint8_t, kFrameBytes> encode(const Frame& f) {
  std::array<std::uint8_t, kFrameBytes> b{};
  b[0] = static_cast<std::uint8_t>((f.read ? 0x80 : 0x00) | (f.index & 0x7F));
  for (int i = 0; i < 8; ++i) b[1 + i] = static_cast<std::uint8_t>(f.data >> (56 - 8 * i));
  return b;
}

constexpr Frame decode(std::span<const std::uint8_t, kFrameBytes> b) {
  Frame f;
  f.read = (b[0] & 0x80) != 0;
  f.index = b[0] & 0x7F;
  for (int i = 0; i < 8; ++i) f.data = (f.data << 8) | b[1 + i];
  return f;
}

inline void append(std::vector<std::uint8_t>& out, const Frame& f) {
  const auto b = encode(f);
  out.insert(out.end(), b.begin(), b.end());
}

// A batch of frames exactly as they travel on the wire (9 bytes each). Used by the socket
// protocol and the backends so register writes are never re-packed on the way to a device.
struct FrameView {
  std::span<const std::uint8_t> bytes;  // size is a multiple of kFrameBytes
  std::size_t size() const { return bytes.size() / kFrameBytes; }
  Frame operator[](std::size_t i) const {
    return decode(std::span<const std::uint8_t, kFrameBytes>(bytes.data() + i * kFrameBytes, kFrameBytes));
  }
};

// Index of the first frame whose R/W̄ bit (bit 7 of byte 0) is set; frames.size() when none is.
// Write batches must not contain reads: every consumer checks with this one routine.
std::size_t first_read_frame(FrameView frames);

}  // namespace gpubridge::protocol
