// decode_png/load_png refuse a PNG whose header claims more pixels than its data could ever hold,
// before allocating the image (fuzz_png: a 20-byte file claiming 16384x16384 made decode_png
// allocate and clear 1 GiB), and still decode highly compressible large images.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>

#include "gpubridge/common/image.hpp"

namespace gpubridge {
namespace {

using Bytes = std::vector<std::uint8_t>;

void put_be32(Bytes& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}

void put_chunk(Bytes& out, const char* type, const Bytes& data) {
  put_be32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  put_be32(out, static_cast<std::uint32_t>(crc32(0, &out[start], static_cast<uInt>(4 + data.size()))));
}

// A 1-bit greyscale PNG whose IDAT holds `raw` deflated at the best ratio zlib has.
Bytes gray1_png(std::uint32_t width, std::uint32_t height, const Bytes& raw) {
  Bytes png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  Bytes ihdr;
  put_be32(ihdr, width);
  put_be32(ihdr, height);
  ihdr.insert(ihdr.end(), {1, 0, 0, 0, 0});
  put_chunk(png, "IHDR", ihdr);
  uLongf packed = compressBound(static_cast<uLong>(raw.size()));
  Bytes idat(packed);
  EXPECT_EQ(compress2(idat.data(), &packed, raw.data(), static_cast<uLong>(raw.size()), 9), Z_OK);
  idat.resize(packed);
  put_chunk(png, "IDAT", idat);
  put_chunk(png, "IEND", {});
  return png;
}

TEST(PngLimits, HeaderClaimingMorePixelsThanTheDataCanHoldIsRefused) {
  const Bytes png = gray1_png(16384, 16384, Bytes(10, 0));  // 1 GiB of RGBA from ~70 bytes
  auto img = decode_png(png, "huge.png");
  ASSERT_FALSE(img);
  EXPECT_NE(img.error().message.find("huge.png: the header says 16384x16384 pixels"), std::string::npos)
      << img.error().message;
  EXPECT_NE(img.error().message.find("truncated or corrupt"), std::string::npos) << img.error().message;

  // The same check on files.
  const auto path = std::filesystem::temp_directory_path() / ("gpubridge-huge-" + std::to_string(::getpid()) + ".png");
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  auto from_file = load_png(path);
  std::filesystem::remove(path);
  ASSERT_FALSE(from_file);
  EXPECT_NE(from_file.error().message.find("truncated or corrupt"), std::string::npos) << from_file.error().message;
}

TEST(PngLimits, MaximallyCompressibleLargeImagesStillDecode) {
  // 4096x4096 1-bit black: about 32768 RGBA bytes per PNG byte, near the real maximum (1032:1
  // deflate times 32:1 expansion), so the plausibility check must not refuse it.
  constexpr std::uint32_t kSide = 4096;
  const Bytes raw(std::size_t{kSide} * (1 + kSide / 8), 0);  // filter byte 0 + packed bits per row
  const Bytes png = gray1_png(kSide, kSide, raw);
  EXPECT_GT(std::uint64_t{kSide} * kSide * 4 / png.size(), 16384u) << "the image is not compressed enough to test the bound";
  auto img = decode_png(png, "black.png");
  ASSERT_TRUE(img) << img.error().message;
  EXPECT_EQ(img->width, kSide);
  EXPECT_EQ(img->height, kSide);
  EXPECT_EQ(img->rgba[0], 0);
  EXPECT_EQ(img->rgba[3], 255);
}

// A caller's own limits (the 64 MiB .upload asset, 1024-texel textures) are checked against the
// header too, so a 70 KB PNG of 4096x4096 is refused without decoding 64 MiB of RGBA first.
TEST(PngLimits, CallerLimitsAreCheckedFromTheHeader) {
  constexpr std::uint32_t kSide = 4096;
  const Bytes png = gray1_png(kSide, kSide, Bytes(std::size_t{kSide} * (1 + kSide / 8), 0));
  PngLimits texture;
  texture.max_side = 1024;
  texture.purpose = "a texture";
  auto img = decode_png(png, "big.png", texture);
  ASSERT_FALSE(img);
  EXPECT_EQ(img.error().message, "big.png: image is 4096x4096; a texture accepts 1..1024 pixels per side");
  PngLimits upload;
  upload.max_pixels = 1u << 20;
  upload.purpose = "an upload";
  img = decode_png(png, "big.png", upload);
  ASSERT_FALSE(img);
  EXPECT_EQ(img.error().message,
            "big.png: image is 4096x4096, more than the 1048576 pixels an upload accepts (checked before decoding)");
  upload.max_pixels = std::uint64_t{kSide} * kSide;
  EXPECT_TRUE(decode_png(png, "big.png", upload));
}

}  // namespace
}  // namespace gpubridge
