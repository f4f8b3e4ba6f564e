// How the examples fit themselves to a device (examples/include/gpubridge/examples/fit.hpp, issue
// 22): which knob gives way first when video memory is short, what a forced size or format the
// device cannot take says, what a device with nothing big enough says, features left out, and the
// painter's-order helper the examples draw with when there is no depth buffer.
#include <gtest/gtest.h>

#include "fallbacks.hpp"
#include "gpubridge/draw/sim_sink.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/examples/golden.hpp"
#include "gpubridge/examples/prediction.hpp"

namespace gpubridge::examples {
namespace {

using protocol::PixelFormat;

DeviceCaps up5k() {
  DeviceCaps d;
  d.name = "up5k";
  d.vram_bytes = 128 * 1024;
  d.max_width = 320;
  d.max_height = 240;
  return d;
}

bool mentions(const std::vector<std::string>& lines, const std::string& text) {
  for (const auto& l : lines)
    if (l.find(text) != std::string::npos) return true;
  return false;
}

TEST(ParseSize, TakesWidthByHeight) {
  auto s = parse_size("320x240");
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(*s, (std::pair{320u, 240u}));
  for (const char* bad : {"", "320", "x240", "320x", "0x240", "320x0", "320x240x", "-1x5", "99999x10", "32ox240"}) {
    auto r = parse_size(bad);
    ASSERT_FALSE(r) << bad;
    EXPECT_NE(r.error().message.find("expected WIDTHxHEIGHT"), std::string::npos) << r.error().message;
  }
}

TEST(Fit, EverythingWantedFitsOnALargeDevice) {
  Wants w;
  w.textures = {{"t", 64, 64, PixelFormat::RGBA8888}};
  auto f = fit(w, DeviceCaps{});
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->context.width, 320u);
  EXPECT_EQ(f->context.format, PixelFormat::RGBA8888);
  EXPECT_TRUE(f->context.double_buffer && f->context.depth_buffer);
  EXPECT_FALSE(f->dither);
  // Two colour buffers, a depth buffer and the texture, each placed on the allocator's alignment.
  EXPECT_GE(f->vram_bytes, 320u * 240 * 4 * 3 + 64 * 64 * 4);
  EXPECT_TRUE(f->gave_up.empty());
}

TEST(Fit, TheLastKeptKnobGivesWayFirst) {
  // 320x240 RGBA8888, double-buffered with depth is 900 KiB; 128 KiB takes 320x240 RGBA2222 alone.
  Wants w;
  auto f = fit(w, up5k());
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->context.width, 320u);
  EXPECT_EQ(f->context.format, PixelFormat::RGBA2222);
  EXPECT_FALSE(f->context.double_buffer);
  EXPECT_FALSE(f->context.depth_buffer);
  EXPECT_TRUE(f->dither) << "a reduced format is dithered where the device has the dither";
  EXPECT_LE(f->vram_bytes, 128u * 1024);
  EXPECT_TRUE(mentions(f->gave_up, "RGBA8888 -> RGBA2222 with the Bayer dither (video memory)")) << f->summary();
  EXPECT_TRUE(mentions(f->gave_up, "double buffering")) << f->summary();

  // Holding on to double buffering first: the framebuffer shrinks instead.
  w.keep = {Knob::DoubleBuffer, Knob::Size, Knob::Format, Knob::Textures, Knob::Depth};
  auto g = fit(w, up5k());
  ASSERT_TRUE(g) << g.error().message;
  EXPECT_TRUE(g->context.double_buffer);
  EXPECT_EQ(g->context.width, 256u);
  EXPECT_EQ(g->context.height, 192u);
  EXPECT_TRUE(mentions(g->gave_up, "framebuffer 320x240 -> 256x192 (video memory)")) << g->summary();
}

TEST(Fit, TexturesShrinkWhenTheyAreGivenUpFirst) {
  Wants w;
  w.format = PixelFormat::RGBA2222;
  w.double_buffer = false;
  w.depth = false;
  w.textures = {{"big", 256, 256, PixelFormat::RGBA8888}};
  w.keep = {Knob::Size, Knob::Format, Knob::DoubleBuffer, Knob::Depth, Knob::Textures};
  auto f = fit(w, up5k());
  ASSERT_TRUE(f) << f.error().message;
  // 76,800 bytes of framebuffer leave room for 128x128 RGB565 (32 KiB), not 256x256 RGB565 (128 KiB).
  ASSERT_EQ(f->textures.size(), 1u);
  EXPECT_EQ(f->texture(0).format, PixelFormat::RGB565);
  EXPECT_EQ(f->texture(0).width, 128u);
  EXPECT_TRUE(mentions(f->gave_up, "texture big 256x256 RGBA8888 -> 128x128 RGB565 (video memory)")) << f->summary();
}

TEST(Fit, FormatsTheDeviceLacksAreNeverChosen) {
  DeviceCaps d = up5k();
  d.features = kDither | kRgba2222 | kTexturing;
  Wants w;
  w.format = PixelFormat::RGB565;
  w.textures = {{"t", 32, 32, PixelFormat::RGB565}};
  auto f = fit(w, d);
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->context.format, PixelFormat::RGBA2222);
  EXPECT_NE(f->texture(0).format, PixelFormat::RGB565);
  EXPECT_FALSE(f->texture(0).bilinear);
}

TEST(Fit, ForcedChoicesTheDeviceCannotTakeAreErrors) {
  FitRequest big;
  big.size = std::pair{640u, 480u};
  auto f = fit(Wants{}, up5k(), big);
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("--size 640x480 is larger than up5k's largest framebuffer, 320x240"), std::string::npos)
      << f.error().message;

  DeviceCaps no565 = up5k();
  no565.features = kRgba2222 | kTexturing;
  FitRequest rgb565;
  rgb565.format = PixelFormat::RGB565;
  f = fit(Wants{}, no565, rgb565);
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("lack rgb565"), std::string::npos) << f.error().message;
}

TEST(Fit, ForcedChoicesAreHonouredAndNamed) {
  FitRequest r;
  r.size = std::pair{160u, 120u};
  r.format = PixelFormat::RGB565;
  r.no_depth = true;
  r.without = kBlend;
  Wants w;
  w.without_feature = {{kBlend, "opaque water"}};
  auto f = fit(w, DeviceCaps{}, r);
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->context.width, 160u);
  EXPECT_EQ(f->context.format, PixelFormat::RGB565);
  EXPECT_FALSE(f->context.depth_buffer);
  EXPECT_FALSE(f->has(kBlend));
  EXPECT_TRUE(mentions(f->gave_up, "(--size)"));
  EXPECT_TRUE(mentions(f->gave_up, "(--format)"));
  EXPECT_TRUE(mentions(f->gave_up, "(--no-depth)"));
  EXPECT_TRUE(mentions(f->gave_up, "blend: opaque water (--without blend)"));
}

TEST(Fit, NothingFitsSaysWhatTheSmallestNeeds) {
  DeviceCaps tiny = up5k();
  tiny.vram_bytes = 2048;
  auto f = fit(Wants{}, tiny);
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("nothing fits in up5k's 2048 bytes of video memory"), std::string::npos)
      << f.error().message;
  // The smallest candidate: 64x48 (a fifth of 320x240) RGBA2222, one buffer, no depth.
  EXPECT_NE(f.error().message.find("(64x48 RGBA2222) needs 3072 bytes"), std::string::npos) << f.error().message;
}

TEST(DeviceCaps, FeaturesComeFromTheCapsRegister) {
  backends::DeviceInfo info;
  info.board = "icebreaker";
  info.vram_bytes = 128 * 1024;
  info.max_width = 320;
  info.max_height = 240;
  // CAPS.FEATURES is bits 56..63: dither and RGBA2222 only.
  info.caps = std::uint64_t{kDither | kRgba2222} << 56;
  const auto d = DeviceCaps::from(info);
  EXPECT_EQ(d.name, "icebreaker");
  EXPECT_EQ(d.vram_bytes, 128u * 1024);
  EXPECT_TRUE(d.has(kDither | kRgba2222 | kTexturing));
  EXPECT_FALSE(d.has(kRgb565));
  EXPECT_FALSE(d.has(kBlend));
  // No CAPS word (a description without one): every feature.
  info.caps = 0;
  EXPECT_TRUE(DeviceCaps::from(info).has(kBlend | kRgb565 | kBilinear));
}

TEST(Context, RefusesAFramebufferLargerThanTheDevicesLargest) {
  sim::DeviceOptions small;
  small.max_width = 320;
  small.max_height = 240;
  auto sink = draw::SimulatorSink::create(small);
  ASSERT_TRUE(sink) << sink.error().message;
  draw::ContextOptions o;
  o.width = 640;
  o.height = 480;
  auto ctx = draw::Context::create(**sink, o);
  ASSERT_FALSE(ctx);
  EXPECT_NE(ctx.error().message.find("framebuffer 640x480 is larger than the device's largest, 320x240"), std::string::npos)
      << ctx.error().message;
}

TEST(Examples, EveryExampleFitsEveryGoldenClassWithinItsMemory) {
  for (const auto& cls : golden_classes())
    for (auto& ex : make_examples()) {
      auto f = configure(*ex, cls.device);
      ASSERT_TRUE(f) << cls.name << " " << ex->info().name << ": " << f.error().message;
      EXPECT_LE(f->vram_bytes, cls.device.vram_bytes) << cls.name << " " << ex->info().name;
      EXPECT_LE(f->context.width, cls.device.max_width);
      EXPECT_EQ(f->features & ~cls.device.features, 0) << "uses a feature the device lacks";
      EXPECT_EQ(ex->options().width, f->context.width) << "configure() is what options() follows";
    }
}

TEST(Prediction, TextureUploadsInTheFrameTravelTheLink) {
  // cubes re-uploads its 32x32 RGBA8888 label every frame: 4 KiB is 1 MEM_ADDR + 512 MEM_DATA
  // frames on a board, which the simulator (taking uploads straight into memory) does not count.
  const BoardLink link{"test", 50, 30, false};
  auto cubes = make_example("cubes");
  auto p = predict_frame(*cubes, DeviceCaps{}, link);
  ASSERT_TRUE(p) << p.error().message;
  EXPECT_GE(p->work.frames_received, 513u);
  EXPECT_GE(p->work.mem_data_writes, 512u);
  EXPECT_NEAR(p->estimate.spi_ms, p->work.frames_received * 72 / 30e3, 0.1);
  // The tetrahedron uploads its texture once, in setup: the frame itself is a few dozen frames.
  auto tetra = make_example("tetrahedron");
  auto q = predict_frame(*tetra, DeviceCaps{}, link);
  ASSERT_TRUE(q) << q.error().message;
  EXPECT_LT(q->work.frames_received, 100u);
  EXPECT_EQ(q->work.mem_data_writes, 0u);
  EXPECT_GT(q->fps, 0);
}

TEST(Painter, FarToNearKeepsTrianglesWholeAndOrdersThemByDistance) {
  const std::vector<std::uint32_t> indices{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
  const std::vector<double> distance{2.0, 5.0, 2.0, 7.0};
  const auto out = far_to_near(indices, distance);
  // 7 (triangle 3), 5 (1), then the two at 2 in their original order (0, 2).
  EXPECT_EQ(out, (std::vector<std::uint32_t>{9, 10, 11, 3, 4, 5, 0, 1, 2, 6, 7, 8}));
}

}  // namespace
}  // namespace gpubridge::examples
