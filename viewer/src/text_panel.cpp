#include "gpubridge/viewer/text_panel.hpp"

#include <algorithm>

#include "gpubridge/viewer/font8x8.hpp"

namespace gpubridge::viewer {

Image render_text_panel(const std::vector<std::string>& input, unsigned scale) {
  scale = std::clamp(scale, 1u, kMaxPanelScale);
  std::vector<std::string> lines(input.begin(), input.begin() + std::min(input.size(), kMaxPanelLines));
  for (auto& line : lines) {
    if (line.size() > kMaxPanelLineChars) line = line.substr(0, kMaxPanelLineChars - 3) + "...";
  }
  std::size_t columns = 0;
  for (const auto& line : lines) columns = std::max(columns, line.size());
  Image img;
  if (lines.empty() || columns == 0) return img;
  img.width = static_cast<unsigned>((2 * kPanelPadding + kGlyphSize * columns) * scale);
  img.height = static_cast<unsigned>((2 * kPanelPadding + kGlyphSize * lines.size()) * scale);
  img.rgba.assign(std::size_t{img.width} * img.height * 4, 0);
  for (std::size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = kPanelAlpha;

  for (std::size_t row = 0; row < lines.size(); ++row) {
    for (std::size_t col = 0; col < lines[row].size(); ++col) {
      const auto& bits = glyph(lines[row][col]);
      const unsigned x0 = static_cast<unsigned>((kPanelPadding + kGlyphSize * col) * scale);
      const unsigned y0 = static_cast<unsigned>((kPanelPadding + kGlyphSize * row) * scale);
      for (unsigned gy = 0; gy < kGlyphSize; ++gy) {
        for (unsigned gx = 0; gx < kGlyphSize; ++gx) {
          if (!((bits[gy] >> gx) & 1u)) continue;
          for (unsigned sy = 0; sy < scale; ++sy) {
            for (unsigned sx = 0; sx < scale; ++sx) {
              std::uint8_t* p = img.pixel(x0 + gx * scale + sx, y0 + gy * scale + sy);
              p[0] = p[1] = p[2] = p[3] = 255;
            }
          }
        }
      }
    }
  }
  return img;
}

}  // namespace gpubridge::viewer
