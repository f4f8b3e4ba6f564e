#include "gpubridge/protocol/crc32.hpp"

#include <zlib.h>

namespace gpubridge::protocol {

std::uint32_t crc32_update(std::uint32_t crc, std::span<const std::uint8_t> bytes) {
  // zlib's crc32 takes uInt lengths; feed large spans in pieces.
  uLong c = crc;
  const std::uint8_t* p = bytes.data();
  std::size_t n = bytes.size();
  while (n > 0) {
    const uInt chunk = n > (1u << 30) ? (1u << 30) : static_cast<uInt>(n);
    c = ::crc32(c, p, chunk);
    p += chunk;
    n -= chunk;
  }
  return static_cast<std::uint32_t>(c);
}

}  // namespace gpubridge::protocol
