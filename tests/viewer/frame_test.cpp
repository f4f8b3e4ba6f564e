// Frames: validation limits, expansion to RGBA (checked against hand-computed bit replication),
// CRC check, and the test pattern against its documented formula.
#include <gtest/gtest.h>

#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/viewer/frame.hpp"
#include "gpubridge/viewer/test_frame_source.hpp"

namespace gpubridge::viewer {
namespace {

using protocol::PixelFormat;

Frame make_frame(unsigned w, unsigned h, PixelFormat f) {
  Frame fr;
  fr.width = w;
  fr.height = h;
  fr.format = f;
  fr.pixels.assign(std::size_t{w} * h * protocol::bytes_per_pixel(f), 0);
  return fr;
}

TEST(Frame, AcceptsConsistentFramesUpToTheLimit) {
  EXPECT_EQ(frame_problem(make_frame(1, 1, PixelFormat::RGBA8888)), "");
  EXPECT_EQ(frame_problem(make_frame(1024, 1024, PixelFormat::RGB565)), "");
  EXPECT_EQ(frame_problem(make_frame(1024, 3, PixelFormat::RGBA2222)), "");
}

TEST(Frame, RefusesOversizedEmptyAndShortFrames) {
  EXPECT_NE(frame_problem(make_frame(1025, 1, PixelFormat::RGBA2222)).find("larger than"), std::string::npos);
  EXPECT_NE(frame_problem(make_frame(1, 1025, PixelFormat::RGBA2222)).find("larger than"), std::string::npos);
  EXPECT_NE(frame_problem(make_frame(0, 10, PixelFormat::RGBA8888)).find("empty"), std::string::npos);
  auto short_frame = make_frame(4, 4, PixelFormat::RGB565);
  short_frame.pixels.pop_back();
  EXPECT_NE(frame_problem(short_frame).find("31 pixel bytes, expected 32"), std::string::npos);
  auto bad_format = make_frame(2, 2, PixelFormat::RGBA8888);
  bad_format.format = static_cast<PixelFormat>(7);
  EXPECT_NE(frame_problem(bad_format).find("unknown pixel format"), std::string::npos);
  EXPECT_FALSE(frame_to_image(short_frame).ok());
}

TEST(Frame, ExpandsRgb565BigEndianWithBitReplication) {
  auto f = make_frame(2, 1, PixelFormat::RGB565);
  // 0xF800 = pure red (r=31); 0x07E0 would be green. Second pixel: r=1, g=1, b=1 -> 0x0821.
  f.pixels = {0xF8, 0x00, 0x08, 0x21};
  auto img = frame_to_image(f);
  ASSERT_TRUE(img.ok());
  const std::uint8_t* p0 = img->pixel(0, 0);
  EXPECT_EQ(p0[0], 255); EXPECT_EQ(p0[1], 0); EXPECT_EQ(p0[2], 0); EXPECT_EQ(p0[3], 255);
  const std::uint8_t* p1 = img->pixel(1, 0);
  // 5-bit 1 -> 00001 000 | 00 = 8; 6-bit 1 -> 000001 00 | 00 = 4.
  EXPECT_EQ(p1[0], 8); EXPECT_EQ(p1[1], 4); EXPECT_EQ(p1[2], 8); EXPECT_EQ(p1[3], 255);
}

TEST(Frame, ExpandsRgba2222) {
  auto f = make_frame(1, 1, PixelFormat::RGBA2222);
  f.pixels = {0b11'10'01'00};
  auto img = frame_to_image(f);
  ASSERT_TRUE(img.ok());
  const std::uint8_t* p = img->pixel(0, 0);
  EXPECT_EQ(p[0], 255); EXPECT_EQ(p[1], 170); EXPECT_EQ(p[2], 85); EXPECT_EQ(p[3], 0);
}

TEST(Frame, CrcMatchesOnlyTheBytesItWasComputedFor) {
  auto f = make_frame(3, 2, PixelFormat::RGBA8888);
  f.pixels[5] = 42;
  f.crc = protocol::crc32(f.pixels);
  EXPECT_TRUE(crc_matches(f));
  f.pixels[0] ^= 1;
  EXPECT_FALSE(crc_matches(f));
}

TEST(TestPattern, FollowsTheDocumentedFormulaInEveryFormat) {
  for (auto format : {PixelFormat::RGBA8888, PixelFormat::RGB565, PixelFormat::RGBA2222}) {
    TestPatternSpec spec{37, 19, format, 60};
    const Frame f = make_test_frame(spec, 300, 1234);
    ASSERT_EQ(frame_problem(f), "");
    EXPECT_EQ(f.number, 300u);
    EXPECT_EQ(f.swap_ns, 1234u);
    EXPECT_TRUE(crc_matches(f));
    const unsigned bpp = protocol::bytes_per_pixel(format);
    for (unsigned y = 0; y < spec.height; ++y) {
      for (unsigned x = 0; x < spec.width; ++x) {
        const unsigned r = (x + 300) % 256, g = y, b = ((x / 8 + y / 8) % 2) ? 255 : 0;
        const std::uint8_t* p = f.pixels.data() + (y * spec.width + x) * bpp;
        switch (format) {
          case PixelFormat::RGBA8888:
            ASSERT_EQ(p[0], r); ASSERT_EQ(p[1], g); ASSERT_EQ(p[2], b); ASSERT_EQ(p[3], 255);
            break;
          case PixelFormat::RGB565:
            ASSERT_EQ((p[0] << 8) | p[1], ((r >> 3) << 11) | ((g >> 2) << 5) | (b >> 3)) << x << "," << y;
            break;
          default:
            ASSERT_EQ(p[0], ((r >> 6) << 6) | ((g >> 6) << 4) | ((b >> 6) << 2) | 3) << x << "," << y;
        }
      }
    }
  }
}

TEST(TestPattern, ParsesSpecsAndRefusesBadOnes) {
  auto s = parse_test_pattern_spec("320x240:rgb565@30");
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s->width, 320u);
  EXPECT_EQ(s->height, 240u);
  EXPECT_EQ(s->format, PixelFormat::RGB565);
  EXPECT_EQ(s->fps, 30u);
  auto plain = parse_test_pattern_spec("8x9");
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(plain->format, PixelFormat::RGBA8888);
  for (const char* bad : {"", "x", "10", "0x10", "2000x10", "10x10:rgb999", "10x10@0", "10x10@99999", "-1x5",
                          "10x10@", "10x 10", "99999999999x1"}) {
    auto r = parse_test_pattern_spec(bad);
    EXPECT_FALSE(r.ok()) << bad;
    if (!r.ok()) {
      EXPECT_NE(r.error().message.find("expected WxH"), std::string::npos) << bad;
    }
  }
}

}  // namespace
}  // namespace gpubridge::viewer
