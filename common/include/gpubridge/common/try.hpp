#pragma once
// Early return for functions that return a Result: GPUBRIDGE_TRY(expr) returns expr's error if it
// has one; GPUBRIDGE_TRY_SET(dst, expr) does the same, else assigns expr's value to dst.
#include "gpubridge/common/result.hpp"

#define GPUBRIDGE_TRY(expr)         \
  do {                              \
    auto try_ = (expr);             \
    if (!try_) return try_.error(); \
  } while (0)
#define GPUBRIDGE_TRY_SET(dst, expr) \
  do {                               \
    auto try_ = (expr);              \
    if (!try_) return try_.error();  \
    dst = *try_;                     \
  } while (0)
