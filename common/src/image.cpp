#include "gpubridge/common/image.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>

#include <png.h>

#include "gpubridge/protocol/pixel.hpp"

namespace gpubridge {
namespace {

// Most RGBA bytes one byte of PNG data can decode to: deflate expands at most 1032:1 and a 1-bit
// pixel becomes 4 RGBA bytes (32:1), so no valid PNG comes near 65536:1.
constexpr std::uint64_t kMaxExpansion = 1u << 16;

// png_bytes: size of the PNG data (0 = unknown, no plausibility check).
Result<Image> decode_with(png_image& img, const std::string& name, std::uint64_t png_bytes, const PngLimits& limits) {
  const std::string dims = std::to_string(img.width) + "x" + std::to_string(img.height);
  const unsigned side = std::min(limits.max_side, kMaxImageDim);
  const std::string purpose = limits.purpose.empty() ? "gpubridge" : limits.purpose;
  if (img.width == 0 || img.height == 0 || img.width > side || img.height > side) {
    png_image_free(&img);
    return make_error(name + ": image is " + dims + "; " + purpose + " accepts 1.." + std::to_string(side) +
                      " pixels per side");
  }
  if (limits.max_pixels != 0 && std::uint64_t{img.width} * img.height > limits.max_pixels) {
    png_image_free(&img);
    return make_error(name + ": image is " + dims + ", more than the " + std::to_string(limits.max_pixels) + " pixels " +
                      purpose + " accepts (checked before decoding)");
  }
  // The header alone must not buy a huge allocation: a 20-byte file claiming 16384x16384 pixels
  // made us allocate and clear 1 GiB before libpng found the data missing (found with fuzz_png).
  const std::uint64_t rgba_bytes = std::uint64_t{img.width} * img.height * 4;
  if (png_bytes != 0 && rgba_bytes > png_bytes * kMaxExpansion) {
    png_image_free(&img);
    return make_error(name + ": the header says " + dims + " pixels but the file has only " + std::to_string(png_bytes) +
                      " bytes, too few for that image; the PNG is truncated or corrupt");
  }
  img.format = PNG_FORMAT_RGBA;
  Image out;
  out.width = img.width;
  out.height = img.height;
  out.rgba.resize(PNG_IMAGE_SIZE(img));
  if (!png_image_finish_read(&img, nullptr, out.rgba.data(), 0, nullptr)) {
    std::string msg = name + ": cannot decode PNG (" + img.message + ")";
    png_image_free(&img);
    return make_error(msg);
  }
  return out;
}

}  // namespace

Result<Image> load_png(const std::filesystem::path& path, const PngLimits& limits) {
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path.c_str())) {
    std::string msg = path.string() + ": not a readable PNG file (" + img.message + ")";
    png_image_free(&img);
    return make_error(msg);
  }
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);  // not a regular file (a pipe): no check
  return decode_with(img, path.string(), ec ? 0 : size, limits);
}

Result<Image> decode_png(std::span<const std::uint8_t> bytes, const std::string& name, const PngLimits& limits) {
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&img, bytes.data(), bytes.size())) {
    std::string msg = name + ": not a PNG image (" + img.message + ")";
    png_image_free(&img);
    return make_error(msg);
  }
  return decode_with(img, name, bytes.size(), limits);
}

Result<void> save_png(const std::filesystem::path& path, const Image& img) {
  png_image p;
  std::memset(&p, 0, sizeof p);
  p.version = PNG_IMAGE_VERSION;
  p.width = img.width;
  p.height = img.height;
  p.format = PNG_FORMAT_RGBA;
  if (img.rgba.size() != std::size_t{img.width} * img.height * 4)
    return make_error(path.string() + ": image buffer size does not match " + std::to_string(img.width) + "x" +
                      std::to_string(img.height));
  if (!png_image_write_to_file(&p, path.c_str(), 0, img.rgba.data(), 0, nullptr)) {
    std::string msg = path.string() + ": cannot write PNG (" + p.message + "); check the directory exists and is writable";
    png_image_free(&p);
    return make_error(msg);
  }
  return {};
}

Result<std::vector<std::uint8_t>> encode_png(const Image& img) {
  png_image p;
  std::memset(&p, 0, sizeof p);
  p.version = PNG_IMAGE_VERSION;
  p.width = img.width;
  p.height = img.height;
  p.format = PNG_FORMAT_RGBA;
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&p, nullptr, &size, 0, img.rgba.data(), 0, nullptr))
    return make_error(std::string("cannot encode PNG: ") + p.message);
  std::vector<std::uint8_t> out(size);
  if (!png_image_write_to_memory(&p, out.data(), &size, 0, img.rgba.data(), 0, nullptr))
    return make_error(std::string("cannot encode PNG: ") + p.message);
  out.resize(size);
  return out;
}

Image image_from_device(protocol::PixelFormat f, unsigned width, unsigned height, std::span<const std::uint8_t> bytes) {
  Image img;
  img.width = width;
  img.height = height;
  img.rgba.resize(std::size_t{width} * height * 4);
  const unsigned bpp = protocol::bytes_per_pixel(f);
  const std::size_t n = std::min<std::size_t>(std::size_t{width} * height, bytes.size() / bpp);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = protocol::load_pixel(f, bytes.data() + i * bpp);
    std::uint8_t* d = img.rgba.data() + i * 4;
    d[0] = c.r; d[1] = c.g; d[2] = c.b; d[3] = c.a;
  }
  return img;
}

std::vector<std::uint8_t> device_from_image(protocol::PixelFormat f, const Image& img) {
  const unsigned bpp = protocol::bytes_per_pixel(f);
  std::vector<std::uint8_t> out(std::size_t{img.width} * img.height * bpp);
  for (std::size_t i = 0; i < std::size_t{img.width} * img.height; ++i) {
    const std::uint8_t* s = img.rgba.data() + i * 4;
    protocol::store_pixel(f, out.data() + i * bpp, {s[0], s[1], s[2], s[3]});
  }
  return out;
}

}  // namespace gpubridge
