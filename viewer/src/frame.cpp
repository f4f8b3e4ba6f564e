#include "gpubridge/viewer/frame.hpp"

#include <fmt/format.h>

#include "gpubridge/protocol/crc32.hpp"

namespace gpubridge::viewer {

std::string frame_problem(const Frame& f) {
  if (f.width == 0 || f.height == 0) return fmt::format("frame {}: empty size {}x{}", f.number, f.width, f.height);
  if (f.width > kMaxFrameDim || f.height > kMaxFrameDim) {
    return fmt::format("frame {}: {}x{} is larger than the viewer's limit of {}x{}", f.number, f.width, f.height,
                       kMaxFrameDim, kMaxFrameDim);
  }
  const auto fmt_index = static_cast<unsigned>(f.format);
  if (fmt_index > static_cast<unsigned>(protocol::PixelFormat::RGBA2222)) {
    return fmt::format("frame {}: unknown pixel format {}", f.number, fmt_index);
  }
  const std::size_t expected = std::size_t{f.width} * f.height * protocol::bytes_per_pixel(f.format);
  if (f.pixels.size() != expected) {
    return fmt::format("frame {}: {} pixel bytes, expected {} for {}", f.number, f.pixels.size(), expected,
                       describe_size(f));
  }
  return {};
}

Result<Image> frame_to_image(const Frame& f) {
  if (auto problem = frame_problem(f); !problem.empty()) return make_error(std::move(problem));
  if (f.format == protocol::PixelFormat::RGBA8888) {  // already R, G, B, A bytes: no per-pixel work
    Image img;
    img.width = f.width;
    img.height = f.height;
    img.rgba = f.pixels;
    return img;
  }
  return image_from_device(f.format, f.width, f.height, f.pixels);
}

bool crc_matches(const Frame& f) { return protocol::crc32(f.pixels) == f.crc; }

std::string describe_size(const Frame& f) {
  return fmt::format("{}x{} {}", f.width, f.height, protocol::to_string(f.format));
}

}  // namespace gpubridge::viewer
