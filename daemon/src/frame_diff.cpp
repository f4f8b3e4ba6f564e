#include "gpubridge/daemon/frame_diff.hpp"

#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/pixel.hpp"

namespace gpubridge::daemon {

std::shared_ptr<const backends::ScanoutFrame> diff_frame(const backends::ScanoutFrame& board,
                                                         const backends::ScanoutFrame& model, std::uint64_t* differing) {
  const std::size_t count = std::size_t{board.width} * board.height;
  const std::size_t board_bpp = protocol::bytes_per_pixel(board.format);
  const std::size_t model_bpp = protocol::bytes_per_pixel(model.format);
  if (board.pixels.empty() || model.pixels.empty() || board.pixels.size() != count * board_bpp) return nullptr;
  const bool same_size = board.width == model.width && board.height == model.height &&
                         model.pixels.size() == std::size_t{model.width} * model.height * model_bpp;

  auto out = std::make_shared<backends::ScanoutFrame>();
  out->number = board.number;
  out->width = board.width;
  out->height = board.height;
  out->format = protocol::PixelFormat::RGBA8888;
  out->swap_time = board.swap_time;
  out->pixels.resize(count * 4);
  std::uint64_t magenta = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const auto b = protocol::load_pixel(board.format, board.pixels.data() + i * board_bpp);
    bool equal = false;
    if (same_size) {
      const auto m = protocol::load_pixel(model.format, model.pixels.data() + i * model_bpp);
      equal = b == m;
    }
    std::uint8_t* o = out->pixels.data() + i * 4;
    if (equal) {
      const auto g = diff_grey(b.r, b.g, b.b);
      o[0] = o[1] = o[2] = g;
      o[3] = 255;
    } else {
      for (int c = 0; c < 4; ++c) o[c] = kDiffMagenta[c];
      ++magenta;
    }
  }
  out->crc = protocol::crc32(out->pixels);
  if (differing) *differing = magenta;
  return out;
}

}  // namespace gpubridge::daemon
