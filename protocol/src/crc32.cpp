#include "gpubridge/protocol/crc32.hpp"

#include <zlib.h>

#include "crc32_clmul.hpp"

namespace gpubridge::protocol {
namespace {

std::uint32_t crc32_zlib(std::uint32_t crc, const std::uint8_t* p, std::size_t n) {
  // zlib's crc32 takes uInt lengths; feed large spans in pieces.
  uLong c = crc;
  while (n > 0) {
    const uInt chunk = n > (1u << 30) ? (1u << 30) : static_cast<uInt>(n);
    c = ::crc32(c, p, chunk);
    p += chunk;
    n -= chunk;
  }
  return static_cast<std::uint32_t>(c);
}

}  // namespace

std::uint32_t crc32_update(std::uint32_t crc, std::span<const std::uint8_t> bytes) {
  const std::uint8_t* p = bytes.data();
  std::size_t n = bytes.size();
  // Whole 16-byte blocks by folding where the CPU can (link CRC, FRAME_CRC, memory CRCs), the
  // tail and short runs by zlib's tables. zlib's convention inverts the register on entry and exit.
  if (n >= detail::kClmulMinBytes && detail::crc32_clmul_supported()) {
    const std::size_t body = n & ~std::size_t{15};
    crc = ~detail::crc32_clmul(~crc, p, body);
    p += body;
    n -= body;
  }
  return crc32_zlib(crc, p, n);
}

}  // namespace gpubridge::protocol
