// The fill ceiling (see FillCeiling in accuracy_bench.hpp).
#include "fill_ceiling.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

namespace gpubridge::bench {
namespace {

using V16 = std::uint32_t __attribute__((vector_size(64)));

// One pass over n pixels (n a multiple of 16): Z = min(Z, z_in) is depth LESS with the write of
// the passing value, and z_in below every stored Z makes every pixel pass, as in the front-Z scenes;
// the colour is written unconditionally (every pixel passes). 16 lanes: one AVX-512 vector, two
// AVX2 vectors or four SSE2 vectors per step, chosen at run time.
__attribute__((target_clones("avx512f", "avx2", "default"))) void fill_pass(std::uint32_t* __restrict z,
                                                                             std::uint32_t* __restrict c, std::size_t n,
                                                                             std::uint32_t z_in, std::uint32_t colour) {
  V16 zin, col;
  for (int k = 0; k < 16; ++k) zin[k] = z_in, col[k] = colour;
  for (std::size_t i = 0; i < n; i += 16) {
    V16 old;
    std::memcpy(&old, z + i, sizeof old);
    const V16 pass = (V16)(zin < old);
    const V16 out = (old & ~pass) | (zin & pass);
    std::memcpy(z + i, &out, sizeof out);
    std::memcpy(c + i, &col, sizeof col);
  }
}

// Best wall-clock Mpix/s of `threads` threads, each making `passes` passes over its own `pixels`.
double measure(unsigned threads, std::size_t pixels, unsigned passes, unsigned runs) {
  pixels = (pixels + 15) & ~std::size_t{15};
  // Cache-line aligned rows, as a renderer's tiles are: 16 spare words to align into.
  std::vector<std::vector<std::uint32_t>> zbuf(threads), cbuf(threads);
  std::vector<std::uint32_t*> z(threads), c(threads);
  auto aligned = [](std::vector<std::uint32_t>& v) {
    return v.data() + (16 - (reinterpret_cast<std::uintptr_t>(v.data()) / 4) % 16) % 16;
  };
  for (unsigned t = 0; t < threads; ++t) {
    zbuf[t].assign(pixels + 16, 0xFFFFFFu), cbuf[t].assign(pixels + 16, 0);
    z[t] = aligned(zbuf[t]), c[t] = aligned(cbuf[t]);
  }
  double best = 1e30;
  std::uint32_t z_in = 0xFFFFFEu;
  for (unsigned r = 0; r <= runs; ++r) {  // run 0 warms up (pages, caches)
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < threads; ++t)
      pool.emplace_back([&, t, first = z_in] {
        for (unsigned p = 0; p < passes; ++p) fill_pass(z[t], c[t], pixels, first - p, 0xFF00FF00u ^ p);
      });
    for (auto& th : pool) th.join();
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    z_in -= passes;
    if (r > 0) best = std::min(best, sec);
  }
  return double(pixels) * threads * passes / best / 1e6;
}

}  // namespace

std::vector<FillCeiling> measure_fill_ceiling(const std::vector<unsigned>& threads, unsigned runs, bool quick) {
  std::vector<FillCeiling> out;
  for (unsigned t : threads) {
    FillCeiling f;
    f.threads = t;
    __builtin_cpu_init();  // the clone fill_pass's resolver picks, in the same order
    f.vectors = __builtin_cpu_supports("avx512f") ? "AVX-512" : __builtin_cpu_supports("avx2") ? "AVX2" : "SSE2";
    f.cache_mpix_s = measure(t, 2048, quick ? 200 : 20000, runs);
    f.frame_mpix_s = measure(t, 640 * 480 / t, quick ? 4 : 100, runs);
    f.dram_mpix_s = measure(t, (quick ? (4u << 20) : (128u << 20)) / 4 / t, quick ? 1 : 3, runs);
    out.push_back(f);
  }
  return out;
}

}  // namespace gpubridge::bench
