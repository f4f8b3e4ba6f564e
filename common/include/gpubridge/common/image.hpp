#pragma once
// RGBA8888 images and PNG files (libpng). Errors name the file and what is wrong with it.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge {

struct Image {
  unsigned width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // width * height * 4, rows top to bottom

  std::uint8_t* pixel(unsigned x, unsigned y) { return rgba.data() + (std::size_t{y} * width + x) * 4; }
  const std::uint8_t* pixel(unsigned x, unsigned y) const { return rgba.data() + (std::size_t{y} * width + x) * 4; }
  friend bool operator==(const Image&, const Image&) = default;
};

inline constexpr unsigned kMaxImageDim = 16384;  // refuse larger PNGs before allocating

// What a caller accepts, checked against the PNG's header before any pixel is decoded (a 1 MB
// PNG can claim 1 GiB of pixels).
struct PngLimits {
  unsigned max_side = kMaxImageDim;  // pixels per side
  std::uint64_t max_pixels = 0;      // width x height; 0: only max_side applies
  std::string purpose;               // what the limit is for, in the error ("a texture", "an upload")
};

Result<Image> load_png(const std::filesystem::path& path, const PngLimits& limits = {});
Result<Image> decode_png(std::span<const std::uint8_t> bytes, const std::string& name_for_errors,
                         const PngLimits& limits = {});
Result<void> save_png(const std::filesystem::path& path, const Image& img);
Result<std::vector<std::uint8_t>> encode_png(const Image& img);

// Device-format buffer (rows packed, pitch = width * bpp) <-> RGBA8888 image.
Image image_from_device(protocol::PixelFormat f, unsigned width, unsigned height, std::span<const std::uint8_t> bytes);
std::vector<std::uint8_t> device_from_image(protocol::PixelFormat f, const Image& img);

}  // namespace gpubridge
