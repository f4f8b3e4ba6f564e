#pragma once
// CRC-32 as used by FRAME_CRC and LINK_CHECK: IEEE 802.3 / zlib (reflected polynomial
// 0xEDB88320, initial value 0xFFFFFFFF, final XOR 0xFFFFFFFF). crc32("123456789") = 0xCBF43926.
#include <cstdint>
#include <span>

namespace gpubridge::protocol {

// Incremental form: crc = crc32_update(crc, bytes) starting from 0 (zlib convention).
std::uint32_t crc32_update(std::uint32_t crc, std::span<const std::uint8_t> bytes);
inline std::uint32_t crc32(std::span<const std::uint8_t> bytes) { return crc32_update(0, bytes); }

}  // namespace gpubridge::protocol
