#include "rtl_calibration.hpp"

#include <random>

#include "gpubridge/geometry/encode.hpp"
#include "gpubridge/protocol/command_stream.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "gpubridge/sim/device.hpp"
#include "gpubridge/sim/timing.hpp"

namespace gpubridge::cli {
namespace {

using protocol::Reg;

constexpr unsigned kW = 160, kH = 120;
// RGB565 colour, depth and texture fit the up5k's 128 KiB; RGBA8888 colour (ecp5 only) moves the others up
constexpr std::uint32_t kColor = 0, kDepth565 = kW * kH * 2, kDepth8888 = kW * kH * 4;  // 16-byte aligned
constexpr std::uint32_t kTexture = kDepth8888 + kW * kH * 4;
constexpr unsigned kTexLog2 = 6;
// A depth buffer in the colour buffer's SDRAM banks (ecp5): RGBA8888 colour and depth share the
// stride, so at a 4 KiB multiple apart (4 banks of 1 KiB rows) every depth access and colour write
// of a pixel go to one bank's two rows; at kDepth8888 (75 KiB) they are always a bank apart. The
// pair separates the row-miss cost from the pixel cost (docs/protocol.md section 19).
constexpr std::uint32_t kDepthSameBank = 42u << 12;  // past the texture
static_assert(kDepthSameBank >= kTexture + (4u << (2 * kTexLog2)));
static_assert(kDepth8888 % 4096 != 0);

struct Shape {
  const char* name;
  int count;             // triangles in the frame
  int w_min, w_max;      // box width and height ranges, pixels
  int h_min, h_max;
};
// small: setup and per-triangle costs; tall: rows; wide: columns; fat: pixels
constexpr Shape kShapes[] = {
    {"small", 120, 1, 6, 1, 6}, {"tall", 40, 2, 6, 30, 110}, {"wide", 40, 30, 150, 2, 6}, {"fat", 24, 20, 70, 20, 70}};

// Every rectangle here lies within 160 x 120, which scissor_word always accepts.
std::uint64_t scissor(unsigned x0, unsigned y0, unsigned x1, unsigned y1) { return *geometry::scissor_word(x0, y0, x1, y1); }

protocol::CommandStream frame(unsigned mode_class, const Shape& shape, bool bilinear, bool rgba8888, bool depth, std::uint32_t seed,
                              bool same_bank = false) {
  protocol::CommandStream s;
  protocol::CommandStreamWriter w(s);
  std::mt19937 rng(seed);
  w.write(Reg::FB_FORMAT, *geometry::fb_format_word(kW, kH, rgba8888 ? protocol::PixelFormat::RGBA8888
                                                                     : protocol::PixelFormat::RGB565));
  w.write(Reg::FB_DRAW, kColor);
  w.write(Reg::FB_Z, same_bank ? kDepthSameBank : rgba8888 ? kDepth8888 : kDepth565);
  // clears: the whole buffer, a wide strip and a tall one (rows and pixels vary apart)
  w.write(Reg::CLEAR_COLOR, rng());
  w.write(Reg::CLEAR_DEPTH, 0xFFFFFF);
  w.write(Reg::SCISSOR, scissor(0, 0, kW, kH));
  w.write(Reg::CLEAR, 0);
  if (depth) w.write(Reg::CLEAR_Z, 0);  // a device without a depth buffer refuses it (protocol 1.4)
  const unsigned strip = 4 + rng() % 8;
  w.write(Reg::SCISSOR, scissor(0, 10, kW, 10 + strip));
  w.write(Reg::CLEAR, 0);
  w.write(Reg::SCISSOR, scissor(20, 0, 20 + strip, kH));
  if (depth) w.write(Reg::CLEAR_Z, 0);
  w.write(Reg::SCISSOR, scissor(0, 0, kW, kH));
  const bool textured = mode_class & 4;
  if (textured) {
    std::vector<std::uint8_t> texels(std::size_t{4} << (2 * kTexLog2));
    for (auto& b : texels) b = static_cast<std::uint8_t>(rng());
    w.upload(kTexture, std::move(texels));
    w.write(Reg::TEX_BASE, kTexture);
    geometry::TextureFormat tf;
    tf.width = tf.height = 1u << kTexLog2;
    tf.bilinear = bilinear;
    w.write(Reg::TEX_FMT, *geometry::tex_fmt_word(tf));
  }
  // class bits: 1 Gouraud, 2 depth (test LESS and write), 4 textured
  geometry::RenderState mode;
  mode.gouraud = mode_class & 1;
  mode.z_test = mode.z_write = mode_class & 2;
  mode.textured = textured;
  w.write(Reg::TRI_MODE, geometry::tri_mode_word(mode));
  w.write(Reg::PRIM, 0);  // list
  std::uniform_int_distribution<int> wd(shape.w_min * 16, shape.w_max * 16), ht(shape.h_min * 16, shape.h_max * 16);
  for (int i = 0; i < shape.count; ++i) {
    const int bw = wd(rng), bh = ht(rng);
    const int x = static_cast<int>(rng() % (kW * 16 - std::min<unsigned>(bw, kW * 16 - 16)));
    const int y = static_cast<int>(rng() % (kH * 16 - std::min<unsigned>(bh, kH * 16 - 16)));
    // a triangle spanning the box: one corner, the opposite side's two ends at random offsets
    const int xs[3] = {x + static_cast<int>(rng() % (bw + 1)), x, x + bw};
    const int ys[3] = {y, y + bh, y + bh - static_cast<int>(rng() % (bh / 2 + 1))};
    geometry::DeviceTriangle tri;
    for (int k = 0; k < 3; ++k) {  // the draws in this order: colour, S, T, Z
      const auto rgba = static_cast<std::uint32_t>(rng());
      const std::int32_t st = static_cast<std::int32_t>(rng() % (2u << 24)), tt = static_cast<std::int32_t>(rng() % (2u << 24));
      const auto z = static_cast<std::uint32_t>(rng() & 0xFFFFFF);
      tri[k] = {static_cast<std::int16_t>(xs[k]), static_cast<std::int16_t>(ys[k]), z, rgba, 0xFFFFFFFFu, st, tt};
    }
    geometry::encode_triangle(tri, textured, w.frames());
  }
  w.write(Reg::FB_DISPLAY, kColor);
  w.flush();
  return s;
}

}  // namespace

std::vector<CalibrationStream> calibration_streams(bool texturing, bool depth) {
  std::vector<CalibrationStream> out;
  std::uint32_t seed = 20261126;
  for (unsigned m = 0; m < sim::DeviceStats::kModeClasses; ++m) {
    if ((m & 4) && !texturing) continue;
    if ((m & 2) && !depth) continue;
    for (const Shape& shape : kShapes) {
      const std::string base = std::string("calib/") + sim::mode_class_name(m) + "/" + shape.name;
      out.push_back({base, frame(m, shape, false, false, depth, seed++)});
      if (shape.name != std::string_view("fat")) continue;
      if (m & 4) out.push_back({base + "-bilinear", frame(m, shape, true, false, depth, seed++)});
      // 4 bytes a pixel (the ecp5's 16-bit SDRAM: two clocks a colour write); the up5k has no room
      if (texturing) out.push_back({base + "-rgba8888", frame(m, shape, false, true, depth, seed++)});
      // a seed of their own: the frames above stay as they were
      if (texturing && (m & 2))
        out.push_back({base + "-rgba8888-same-bank", frame(m, shape, false, true, depth, 0x5A3EBA00u + m, true)});
    }
  }
  return out;
}

}  // namespace gpubridge::cli
