#pragma once
// What this CPU runs, for the routines compiled once per instruction set and picked at run time
// (span_simd.cpp, preview_plain.cpp). Asked once per process.

namespace gpubridge::sim {

inline bool cpu_has_avx2() {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
}

// The AVX-512 subsets the AVX-512 instances are compiled for: F, VL, BW and DQ.
inline bool cpu_has_avx512() {
  static const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
  return avx512;
}

}  // namespace gpubridge::sim
