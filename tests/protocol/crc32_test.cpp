// crc32_update against zlib's crc32 on random buffers: whole 16-byte blocks go through the
// carry-less-multiplication folding where the CPU has it, the rest through zlib's tables, and the
// two must be one CRC (the link CRC, FRAME_CRC and every memory CRC depend on it).
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <random>
#include <vector>

#include "../../protocol/src/crc32_clmul.hpp"
#include "gpubridge/protocol/crc32.hpp"

namespace gpubridge::protocol {
namespace {

std::uint32_t zlib_crc(std::uint32_t crc, const std::uint8_t* p, std::size_t n) {
  return static_cast<std::uint32_t>(::crc32(crc, p, static_cast<uInt>(n)));
}

TEST(Crc32, MatchesZlibOnRandomBuffersLengthsAndOffsets) {
  std::mt19937 rng(17);
  std::vector<std::uint8_t> buf(70000);
  for (auto& b : buf) b = static_cast<std::uint8_t>(rng());
  for (int i = 0; i < 4000; ++i) {
    // Mostly around the folding thresholds (64-byte minimum, 16-byte blocks), some long runs.
    const std::size_t n = i % 50 == 0 ? rng() % 65536 : rng() % 300;
    const std::size_t at = rng() % 64;  // unaligned starts
    const std::uint32_t init = i % 3 == 0 ? 0 : static_cast<std::uint32_t>(rng());
    const std::uint32_t got = crc32_update(init, std::span(buf.data() + at, n));
    ASSERT_EQ(got, zlib_crc(init, buf.data() + at, n)) << "length " << n << " offset " << at << " initial " << init;
  }
}

TEST(Crc32, IncrementalPiecesEqualOneCall) {
  std::mt19937 rng(3);
  std::vector<std::uint8_t> buf(10000);
  for (auto& b : buf) b = static_cast<std::uint8_t>(rng());
  const std::uint32_t whole = crc32(buf);
  for (int i = 0; i < 200; ++i) {
    std::uint32_t c = 0;
    for (std::size_t at = 0; at < buf.size();) {
      const std::size_t n = std::min<std::size_t>(buf.size() - at, rng() % 400);
      c = crc32_update(c, std::span(buf.data() + at, n));
      at += n;
    }
    ASSERT_EQ(c, whole);
  }
}

// The folding routine itself (crc32_update sends it only whole blocks of 64 bytes or more).
TEST(Crc32, ClmulFoldingMatchesZlibOnWholeBlocks) {
  if (!detail::crc32_clmul_supported()) GTEST_SKIP() << "this CPU has no PCLMULQDQ: crc32_update uses zlib only";
  std::mt19937 rng(5);
  std::vector<std::uint8_t> buf(4096 + 16);
  for (auto& b : buf) b = static_cast<std::uint8_t>(rng());
  for (std::size_t n = detail::kClmulMinBytes; n <= 4096; n += 16) {
    const std::size_t at = rng() % 16;
    const std::uint32_t init = static_cast<std::uint32_t>(rng());
    // zlib's convention inverts the register on entry and exit; the routine works on it raw.
    ASSERT_EQ(~detail::crc32_clmul(~init, buf.data() + at, n), zlib_crc(init, buf.data() + at, n)) << "length " << n;
  }
}

}  // namespace
}  // namespace gpubridge::protocol
