#pragma once
// Text for the overlay, drawn on the CPU with the built-in 8x8 font into an RGBA image that the
// renderer blends over the frame: white glyphs on a translucent black panel.
#include <string>
#include <vector>

#include "gpubridge/common/image.hpp"

namespace gpubridge::viewer {

inline constexpr unsigned kPanelPadding = 4;        // panel pixels around the text (before scaling)
inline constexpr std::uint8_t kPanelAlpha = 176;    // background opacity
inline constexpr unsigned kMaxPanelScale = 8;
inline constexpr std::size_t kMaxPanelLineChars = 160;  // longer lines are cut (with "...")
inline constexpr std::size_t kMaxPanelLines = 64;

// Image of the lines at `scale` (1 .. kMaxPanelScale) pixels per font pixel. Glyph cell (col, row)
// starts at ((kPanelPadding + 8*col) * scale, (kPanelPadding + 8*row) * scale). Empty input gives
// an empty image.
Image render_text_panel(const std::vector<std::string>& lines, unsigned scale);

}  // namespace gpubridge::viewer
