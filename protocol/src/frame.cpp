// Frame batch checks shared by the parser, the command checks and every backend.
#include "gpubridge/protocol/frame.hpp"

#include <bit>
#include <cstring>
#include <utility>

namespace gpubridge::protocol {
namespace {

// Every WRITE_FRAMES byte passes first_read_frame (parser, command checks, backends), so it tests
// 8 frames (72 bytes) per step: on a little-endian host byte 9i of such a block is byte i of its
// 64-bit word i, so one masked OR per word covers it.
template <std::size_t... W>
std::uint64_t read_bits_of_block(const std::uint8_t* block, std::index_sequence<W...>) {
  const auto word = [block](std::size_t w) {
    std::uint64_t v;
    std::memcpy(&v, block + 8 * w, sizeof v);
    return v;
  };
  return ((word(W) & (std::uint64_t{0x80} << (8 * W))) | ...);  // unrolled: constant masks
}

}  // namespace

std::size_t first_read_frame(FrameView frames) {
  const std::span<const std::uint8_t> bytes = frames.bytes;
  const std::size_t n = frames.size();
  std::size_t i = 0;
  if constexpr (std::endian::native == std::endian::little) {
    constexpr std::size_t kBlock = 8;
    for (; i + kBlock <= n; i += kBlock)
      if (read_bits_of_block(bytes.data() + i * kFrameBytes, std::make_index_sequence<kBlock>{}) != 0)
        break;  // the exact frame is found below
  }
  for (; i < n; ++i)
    if (bytes[i * kFrameBytes] & 0x80) return i;
  return n;
}

}  // namespace gpubridge::protocol
