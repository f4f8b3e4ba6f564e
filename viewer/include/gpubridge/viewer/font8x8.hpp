#pragma once
// A built-in 8x8 bitmap font for printable ASCII (32 .. 126): the overlay needs no font files.
#include <array>
#include <cstdint>

namespace gpubridge::viewer {

inline constexpr unsigned kGlyphSize = 8;
inline constexpr char kFirstGlyph = ' ';
inline constexpr char kLastGlyph = '~';

// Rows top to bottom; bit 0 of each row is the leftmost pixel. Characters outside 32 .. 126 map
// to '?'.
const std::array<std::uint8_t, kGlyphSize>& glyph(char c);

}  // namespace gpubridge::viewer
