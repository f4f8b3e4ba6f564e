#pragma once
// The GPU's per-column memories: the double column buffer (colbufs, 2 x 256 entries of
// {light8, index8}; rows 0..239 are sent) and the one-column depth buffer (depths, 240 x 32 bits:
// bit 31 = the draw buffer the depth was written with, bits 30:0 = depth). Neither is ever
// cleared: the tag makes depths from the previous column pass the test, so a row not written in
// column c - 1 tests column c against column c - 2's depth, and a row a column does not write keeps
// the entry of two columns earlier.
#include <array>
#include <cstdint>

#include "gpubridge/dmc1/command.hpp"

namespace gpubridge::dmc1 {

struct ColumnBuffers {
  std::array<std::array<std::uint16_t, 256>, 2> entries{};
  std::array<std::uint32_t, kRows> depth{};
};

// The depth test with its implicit clear: `tag` is the draw buffer in bit 31. A stale entry (other
// tag) xors to a value above any 31-bit depth, so it passes; equal depths pass (lightmap pass).
inline bool depth_passes(std::uint32_t stored, std::uint32_t dist, std::uint32_t tag) { return dist <= (stored ^ tag); }

}  // namespace gpubridge::dmc1
