#include "gpubridge/viewer/layout.hpp"

#include <algorithm>
#include <cstdint>

namespace gpubridge::viewer {

std::string to_string(ScaleMode m) {
  switch (m) {
    case ScaleMode::Fit: return "fit";
    case ScaleMode::Integer: return "integer";
    case ScaleMode::Zoom1: return "1:1";
    case ScaleMode::Zoom2: return "2:1";
    case ScaleMode::Zoom3: return "3:1";
  }
  return "?";
}

namespace {

Rect centred(int window_w, int window_h, std::int64_t w, std::int64_t h) {
  return Rect{static_cast<int>((window_w - w) / 2), static_cast<int>((window_h - h) / 2), static_cast<int>(w),
              static_cast<int>(h)};
}

}  // namespace

Rect frame_rect(int window_w, int window_h, unsigned frame_w, unsigned frame_h, ScaleMode mode) {
  if (window_w <= 0 || window_h <= 0 || frame_w == 0 || frame_h == 0) return {};
  // 64-bit products: window sizes and frame sizes are each < 2^31, so no overflow.
  const std::int64_t fw = frame_w, fh = frame_h, ww = window_w, wh = window_h;
  switch (mode) {
    case ScaleMode::Zoom1: return centred(window_w, window_h, fw, fh);
    case ScaleMode::Zoom2: return centred(window_w, window_h, fw * 2, fh * 2);
    case ScaleMode::Zoom3: return centred(window_w, window_h, fw * 3, fh * 3);
    case ScaleMode::Integer: {
      const std::int64_t factor = std::max<std::int64_t>(1, std::min(ww / fw, wh / fh));
      return centred(window_w, window_h, fw * factor, fh * factor);
    }
    case ScaleMode::Fit: break;
  }
  // Fit: compare aspect ratios exactly (cross-multiplied) and round the other side to nearest.
  if (ww * fh <= wh * fw) {  // window relatively narrower: width-limited
    const std::int64_t h = std::max<std::int64_t>(1, (ww * fh * 2 + fw) / (fw * 2));
    return centred(window_w, window_h, ww, h);
  }
  const std::int64_t w = std::max<std::int64_t>(1, (wh * fw * 2 + fh) / (fh * 2));
  return centred(window_w, window_h, w, wh);
}

Size initial_window_size(unsigned frame_w, unsigned frame_h, int max_w, int max_h) {
  if (frame_w == 0 || frame_h == 0 || max_w <= 0 || max_h <= 0) return {640, 480};
  const std::int64_t fw = frame_w, fh = frame_h;
  const std::int64_t factor = std::max<std::int64_t>(1, std::min<std::int64_t>(max_w / fw, max_h / fh));
  return {static_cast<int>(std::min<std::int64_t>(fw * factor, max_w)),
          static_cast<int>(std::min<std::int64_t>(fh * factor, max_h))};
}

}  // namespace gpubridge::viewer
