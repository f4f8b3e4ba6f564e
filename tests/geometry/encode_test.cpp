// Register frames: field values decoded through the protocol's register table (independent of
// the encoder's own packing) must equal what was asked for.
#include <gtest/gtest.h>

#include "gpubridge/geometry/encode.hpp"

namespace gpubridge::geometry {
namespace {

using protocol::Reg;

std::int64_t field(Reg r, const char* name, std::uint64_t data) {
  const auto* f = protocol::describe(r).field(name);
  EXPECT_NE(f, nullptr) << name;
  return f ? f->get_signed(data) : -1;
}

TEST(Encode, TriangleFramesInRegisterOrder) {
  DeviceTriangle t;
  for (int i = 0; i < 3; ++i) {
    t[i].x = static_cast<std::int16_t>(-100 * i - 7);
    t[i].y = static_cast<std::int16_t>(50 * i);
    t[i].z = 0x123456u + i;
    t[i].rgba = 0x10203040u + i;
    t[i].q = 0xF0000000u + i;
    t[i].s = -5 - i;
    t[i].t = 7 + i;
  }
  std::vector<protocol::Frame> f;
  encode_triangle(t, true, f);
  ASSERT_EQ(f.size(), 9u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(f[3 * i].index, protocol::index_of(Reg::COLOR));
    EXPECT_EQ(f[3 * i + 1].index, protocol::index_of(Reg::TEXCOORD));
    EXPECT_EQ(f[3 * i + 2].index, protocol::index_of(Reg::VERTEX));
    for (int k = 0; k < 3; ++k) {
      EXPECT_FALSE(f[3 * i + k].read);
      EXPECT_EQ(protocol::check_write(f[3 * i + k].index, f[3 * i + k].data).errors, 0);
    }
    EXPECT_EQ(field(Reg::VERTEX, "X", f[3 * i + 2].data), t[i].x);
    EXPECT_EQ(field(Reg::VERTEX, "Y", f[3 * i + 2].data), t[i].y);
    EXPECT_EQ(field(Reg::VERTEX, "Z", f[3 * i + 2].data), t[i].z);
    EXPECT_EQ(field(Reg::COLOR, "Q", f[3 * i].data), t[i].q);
    EXPECT_EQ(field(Reg::COLOR, "R", f[3 * i].data), 0x10);
    EXPECT_EQ(field(Reg::COLOR, "A", f[3 * i].data), 0x40 + i);
    EXPECT_EQ(field(Reg::TEXCOORD, "S", f[3 * i + 1].data), t[i].s);
    EXPECT_EQ(field(Reg::TEXCOORD, "T", f[3 * i + 1].data), t[i].t);
  }
  f.clear();
  encode_triangle(t, false, f);
  EXPECT_EQ(f.size(), 6u);  // no TEXCOORD when untextured
}

TEST(Encode, TriModeFields) {
  RenderState s;
  s.gouraud = false;
  s.textured = true;
  s.z_test = true;
  s.z_func = protocol::DepthFunc::Equal;
  s.blend = protocol::BlendMode::Multiply;
  s.mask_g = true;
  s.tex_decal = true;
  s.dither = s.temporal = true;
  s.dither_phase = 21;  // the frame number: its low four bits are sent
  const auto w = tri_mode_word(s);
  EXPECT_EQ(protocol::check_write(protocol::index_of(Reg::TRI_MODE), w).errors, 0);
  EXPECT_EQ(field(Reg::TRI_MODE, "GOURAUD", w), 0);
  EXPECT_EQ(field(Reg::TRI_MODE, "TEXTURED", w), 1);
  EXPECT_EQ(field(Reg::TRI_MODE, "Z_TEST", w), 1);
  EXPECT_EQ(field(Reg::TRI_MODE, "Z_FUNC", w), 2);
  EXPECT_EQ(field(Reg::TRI_MODE, "Z_WRITE", w), 0);
  EXPECT_EQ(field(Reg::TRI_MODE, "BLEND", w), 3);
  EXPECT_EQ(field(Reg::TRI_MODE, "MASK_G", w), 1);
  EXPECT_EQ(field(Reg::TRI_MODE, "MASK_R", w), 0);
  EXPECT_EQ(field(Reg::TRI_MODE, "TEX_DECAL", w), 1);
  EXPECT_EQ(field(Reg::TRI_MODE, "DITHER", w), 1);
  EXPECT_EQ(field(Reg::TRI_MODE, "TEMPORAL", w), 1);
  EXPECT_EQ(field(Reg::TRI_MODE, "DITHER_PHASE", w), 5);
}

TEST(Encode, DitherPhaseIsSentOnlyWithTheTemporalDither) {
  // A device without CAPS bit 6 flags a non-zero phase; a draw without TEMPORAL must not send one.
  RenderState s;
  s.dither = true;
  s.dither_phase = 7;
  EXPECT_EQ(field(Reg::TRI_MODE, "DITHER_PHASE", tri_mode_word(s)), 0);
  s.temporal = true;
  EXPECT_EQ(field(Reg::TRI_MODE, "DITHER_PHASE", tri_mode_word(s)), 7);
}

TEST(Encode, TexFmtValidatesSizes) {
  TextureFormat t{256, 8, protocol::PixelFormat::RGB565, protocol::Wrap::Mirror, protocol::Wrap::Clamp, true};
  const auto w = tex_fmt_word(t);
  ASSERT_TRUE(w);
  EXPECT_EQ(field(Reg::TEX_FMT, "WIDTH_LOG2", *w), 8);
  EXPECT_EQ(field(Reg::TEX_FMT, "HEIGHT_LOG2", *w), 3);
  EXPECT_EQ(field(Reg::TEX_FMT, "FORMAT", *w), 1);
  EXPECT_EQ(field(Reg::TEX_FMT, "WRAP_S", *w), 2);
  EXPECT_EQ(field(Reg::TEX_FMT, "WRAP_T", *w), 1);
  EXPECT_EQ(field(Reg::TEX_FMT, "BILINEAR", *w), 1);
  for (unsigned bad : {0u, 4u, 12u, 2048u}) {
    t.width = bad;
    EXPECT_FALSE(tex_fmt_word(t)) << bad;
  }
}

TEST(Encode, AddressesFormatAndScissor) {
  EXPECT_FALSE(address16_word(8));
  EXPECT_EQ(field(Reg::FB_DRAW, "ADDR", *address16_word(0x12340)), 0x1234);
  const auto fb = fb_format_word(320, 240, protocol::PixelFormat::RGBA2222);
  ASSERT_TRUE(fb);
  EXPECT_EQ(field(Reg::FB_FORMAT, "WIDTH", *fb), 320);
  EXPECT_EQ(field(Reg::FB_FORMAT, "HEIGHT", *fb), 240);
  EXPECT_EQ(field(Reg::FB_FORMAT, "FORMAT", *fb), 2);
  EXPECT_FALSE(fb_format_word(0, 10, protocol::PixelFormat::RGBA8888));
  EXPECT_FALSE(fb_format_word(1025, 10, protocol::PixelFormat::RGBA8888));
  const auto sc = scissor_word(1, 2, 300, 400);
  ASSERT_TRUE(sc);
  EXPECT_EQ(field(Reg::SCISSOR, "X0", *sc), 1);
  EXPECT_EQ(field(Reg::SCISSOR, "Y0", *sc), 2);
  EXPECT_EQ(field(Reg::SCISSOR, "X1", *sc), 300);
  EXPECT_EQ(field(Reg::SCISSOR, "Y1", *sc), 400);
  EXPECT_FALSE(scissor_word(0, 0, 1025, 1));
}

TEST(Encode, UploadPacksBigEndianWords) {
  const std::uint8_t bytes[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  std::vector<protocol::Frame> f;
  ASSERT_TRUE(encode_upload(0x100, bytes, f));
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].index, protocol::index_of(Reg::MEM_ADDR));
  EXPECT_EQ(field(Reg::MEM_ADDR, "ADDR", f[0].data), 0x100 / 8);
  EXPECT_EQ(f[1].data, 0x0102030405060708ull);
  EXPECT_EQ(f[2].data, 0x090A000000000000ull);
  EXPECT_FALSE(encode_upload(0x104, bytes, f));
}

}  // namespace
}  // namespace gpubridge::geometry
