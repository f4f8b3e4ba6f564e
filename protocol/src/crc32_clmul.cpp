// CRC-32 by folding with PCLMULQDQ (Gopal et al., "Fast CRC Computation for Generic Polynomials
// Using PCLMULQDQ Instruction", Intel 2009). The link CRC covers every frame on the wire, so the
// simulator hashes as many bytes as it decodes: zlib's table-driven crc32 costs about 4
// instructions per byte (35 per 9-byte frame), folding about 0.3.
//
// A 128-bit remainder moves D bits further down the message by multiplying its two halves by
// x^k mod P for the matching k (carry-less, bit-reflected) and adding the data found there; the
// constants below are those residues for D = 512 (four 16-byte lanes, one 64-byte step) and D = 128
// (one lane into the next), then the 64 → 32 bit fold and the Barrett reduction by P with
// mu = floor(x^64 / P). The randomized comparison with zlib (Crc32.ClmulMatchesZlib...) checks them.
#include "crc32_clmul.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define GPUBRIDGE_CRC32_CLMUL 1
#endif

namespace gpubridge::protocol::detail {

#if GPUBRIDGE_CRC32_CLMUL

bool crc32_clmul_supported() {
  static const bool ok = __builtin_cpu_supports("pclmul") && __builtin_cpu_supports("sse4.1");
  return ok;
}

namespace {

#define GPUBRIDGE_CLMUL_TARGET __attribute__((target("pclmul,sse4.1")))

GPUBRIDGE_CLMUL_TARGET inline __m128i load(const std::uint8_t* p) {
  return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
}

// Folds the remainder `x` over the distance the constants `k` (lo: x.lo's, hi: x.hi's) stand for
// and adds the data that lies there.
GPUBRIDGE_CLMUL_TARGET inline __m128i fold(__m128i x, __m128i k, __m128i next) {
  return _mm_xor_si128(_mm_xor_si128(_mm_clmulepi64_si128(x, k, 0x00), _mm_clmulepi64_si128(x, k, 0x11)), next);
}

}  // namespace

GPUBRIDGE_CLMUL_TARGET std::uint32_t crc32_clmul(std::uint32_t raw, const std::uint8_t* p, std::size_t n) {
  const __m128i k512 = _mm_set_epi64x(0x1c6e41596, 0x154442bd4);  // 64-byte step
  const __m128i k128 = _mm_set_epi64x(0x0ccaa009e, 0x1751997d0);  // 16-byte step
  const __m128i k64 = _mm_set_epi64x(0, 0x163cd6124);              // 64 → 32 bits
  const __m128i barrett = _mm_set_epi64x(0x1f7011641, 0x1db710641);  // mu (hi), P (lo)
  const __m128i low32 = _mm_set_epi32(0, 0, 0, -1);

  // Four lanes of 16 bytes; the CRC register enters as the first 32 bits of data.
  __m128i x0 = _mm_xor_si128(load(p), _mm_cvtsi32_si128(static_cast<int>(raw)));
  __m128i x1 = load(p + 16), x2 = load(p + 32), x3 = load(p + 48);
  for (p += 64, n -= 64; n >= 64; p += 64, n -= 64) {
    x0 = fold(x0, k512, load(p));
    x1 = fold(x1, k512, load(p + 16));
    x2 = fold(x2, k512, load(p + 32));
    x3 = fold(x3, k512, load(p + 48));
  }
  // Lanes into one, then the remaining 16-byte blocks.
  __m128i x = fold(fold(fold(x0, k128, x1), k128, x2), k128, x3);
  for (; n >= 16; p += 16, n -= 16) x = fold(x, k128, load(p));

  // 128 → 64 bits (appending the 32 zero bits of the CRC's definition), then 64 → 32.
  x = _mm_xor_si128(_mm_srli_si128(x, 8), _mm_clmulepi64_si128(k128, x, 0x01));
  x = _mm_xor_si128(_mm_srli_si128(x, 4), _mm_clmulepi64_si128(_mm_and_si128(x, low32), k64, 0x00));
  // Barrett reduction: q = (x.lo32 * mu).lo32, crc = (x xor q * P) >> 32.
  __m128i q = _mm_and_si128(_mm_clmulepi64_si128(_mm_and_si128(x, low32), barrett, 0x10), low32);
  x = _mm_xor_si128(x, _mm_clmulepi64_si128(q, barrett, 0x00));
  return static_cast<std::uint32_t>(_mm_extract_epi32(x, 1));
}

#else

bool crc32_clmul_supported() { return false; }
std::uint32_t crc32_clmul(std::uint32_t raw, const std::uint8_t*, std::size_t) { return raw; }

#endif

}  // namespace gpubridge::protocol::detail
