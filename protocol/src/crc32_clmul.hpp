#pragma once
// CRC-32 (reflected 0xEDB88320) by carry-less multiplication, for long runs of bytes. Internal to
// crc32.cpp and its test: crc32_update() is the interface.
#include <cstddef>
#include <cstdint>

namespace gpubridge::protocol::detail {

// Whether this CPU has PCLMULQDQ and SSE4.1 (checked once).
bool crc32_clmul_supported();

// Bytes are folded 64 at a time: shorter runs go to zlib.
inline constexpr std::size_t kClmulMinBytes = 64;

// The raw (not inverted) CRC register after `n` bytes: n >= kClmulMinBytes and a multiple of 16.
// Only call when crc32_clmul_supported().
std::uint32_t crc32_clmul(std::uint32_t raw, const std::uint8_t* p, std::size_t n);

}  // namespace gpubridge::protocol::detail
