#pragma once
// The mirror-mode difference image (docs/protocol.md 17.3, SUBSCRIBE source 2 "diff"): the board's
// frame with every pixel that equals the simulator's pixel dimmed to grey and every pixel that
// differs in bright magenta, so a one-pixel rasteriser bug is visible at a glance.
#include <cstdint>
#include <memory>

#include "gpubridge/backends/backend.hpp"

namespace gpubridge::daemon {

inline constexpr std::uint8_t kDiffMagenta[4] = {255, 0, 255, 255};

// Grey level of an equal pixel: half its luma, (77 R + 150 G + 29 B) / 256 / 2, so the picture stays
// recognisable but never reaches the magenta's brightness.
constexpr std::uint8_t diff_grey(std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  return static_cast<std::uint8_t>(((77u * r + 150u * g + 29u * b) >> 8) / 2);
}

// RGBA8888 frame of the board's size, number and swap time. Pixels compare by their RGBA8888
// expansion; frames of different sizes differ everywhere. Null when either frame has no pixels
// (a CRC-only board). `differing` (optional) receives the number of magenta pixels.
std::shared_ptr<const backends::ScanoutFrame> diff_frame(const backends::ScanoutFrame& board,
                                                         const backends::ScanoutFrame& model,
                                                         std::uint64_t* differing = nullptr);

}  // namespace gpubridge::daemon
