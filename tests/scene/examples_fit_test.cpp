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

TEST(DeviceCaps, DepthBufferFromCaps2OrAnOlderProtocol) {
  backends::DeviceInfo info;
  info.caps = std::uint64_t{kDither} << 56;
  const auto id = [](unsigned minor) { return std::uint64_t{protocol::kIdMagic} << 32 | 1ull << 24 | std::uint64_t{minor} << 16; };
  // 1.4: CAPS2.FEATURES2 bit 0 decides.
  info.id = id(4);
  info.caps2 = 0;
  EXPECT_FALSE(DeviceCaps::from(info).has(kDepthBuffer));
  EXPECT_FALSE(DeviceCaps::from(info).simulator_options().features2 & sim::FEATURE2_DEPTH);
  info.caps2 = protocol::kFeature2Depth;
  EXPECT_TRUE(DeviceCaps::from(info).has(kDepthBuffer));
  EXPECT_EQ(DeviceCaps::from(info).simulator_options().features2, sim::FEATURE2_DEPTH);
  // 1.3 and older have no CAPS2 (the host reads none: 0) and always a depth buffer.
  for (unsigned minor : {0u, 2u, 3u}) {
    info.id = id(minor);
    info.caps2 = 0;
    EXPECT_TRUE(DeviceCaps::from(info).has(kDepthBuffer)) << "1." << minor;
  }
  EXPECT_TRUE(protocol::has_depth_buffer(id(3), 0));
  EXPECT_FALSE(protocol::has_depth_buffer(id(4), 0));
  EXPECT_TRUE(protocol::has_depth_buffer(id(4), 1));
}

TEST(Fit, ADeviceWithoutADepthBufferDrawsInPaintersOrder) {
  DeviceCaps d;  // plenty of memory: only the missing feature can take the depth buffer away
  d.name = "nodepth";
  d.features = static_cast<std::uint16_t>(d.features & ~kDepthBuffer);
  Wants w;
  w.without_depth = "triangles sorted far to near";
  auto f = fit(w, d);
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_FALSE(f->context.depth_buffer);
  EXPECT_TRUE(f->painter());
  EXPECT_TRUE(mentions(f->gave_up, "depth buffer -> triangles sorted far to near (nodepth has no depth buffer (CAPS2))"));
  // --without depth on a device that has one says so instead
  FitRequest r;
  r.without = kDepthBuffer;
  auto g = fit(w, DeviceCaps{}, r);
  ASSERT_TRUE(g) << g.error().message;
  EXPECT_FALSE(g->context.depth_buffer);
  EXPECT_TRUE(mentions(g->gave_up, "(--without depth)"));
  EXPECT_EQ(parse_feature("depth"), kDepthBuffer);
}

TEST(Examples, WithoutADepthBufferNoExampleSendsZ) {
  // The up5k gateware's device (no depth buffer): the simulator configured as it refuses
  // TRI_MODE.Z_TEST / Z_WRITE and CLEAR_Z with ERR_BAD_VALUE, which render_frames reports.
  DeviceCaps d = up5k();
  d.features = static_cast<std::uint16_t>(d.features & ~kDepthBuffer);
  const auto options = d.simulator_options();
  ASSERT_EQ(options.features2, 0);
  for (auto& ex : make_examples()) {
    auto f = configure(*ex, d);
    ASSERT_TRUE(f) << ex->info().name << ": " << f.error().message;
    EXPECT_TRUE(f->painter()) << ex->info().name;
    auto frames = render_frames(*ex, {0, 1}, options);
    EXPECT_TRUE(frames) << (frames ? "" : frames.error().message);
  }
}

// Two overlapping quads: depth-tested (near one drawn first) and in painter's order on a device
// without a depth buffer give the same picture.
TEST(Painter, TwoQuadsMatchTheDepthTestedPicture) {
  using geometry::Vec3;
  using geometry::Vec4;
  const std::vector<draw::Vertex> v{
      // near quad (z 0.25; the depth range is [0, 1]), red, left
      {Vec3{-0.8, -0.6, 0.25}, Vec4{1, 0, 0, 1}}, {Vec3{0.3, -0.6, 0.25}, Vec4{1, 0, 0, 1}},
      {Vec3{0.3, 0.6, 0.25}, Vec4{1, 0, 0, 1}}, {Vec3{-0.8, 0.6, 0.25}, Vec4{1, 0, 0, 1}},
      // far quad (z 0.75), green, right, overlapping the near one
      {Vec3{-0.2, -0.8, 0.75}, Vec4{0, 1, 0, 1}}, {Vec3{0.9, -0.8, 0.75}, Vec4{0, 1, 0, 1}},
      {Vec3{0.9, 0.4, 0.75}, Vec4{0, 1, 0, 1}}, {Vec3{-0.2, 0.4, 0.75}, Vec4{0, 1, 0, 1}}};
  const std::vector<std::uint32_t> near_first{0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
  const auto render = [&](bool depth) -> Result<Image> {
    sim::DeviceOptions o;
    o.features2 = depth ? sim::FEATURE2_DEPTH : 0;
    auto sink = draw::SimulatorSink::create(o);
    if (!sink) return sink.error();
    auto ctx = draw::Context::create(**sink, {.width = 64, .height = 48, .depth_buffer = depth, .double_buffer = false});
    if (!ctx) return ctx.error();
    if (auto r = ctx->clear({0, 0, 0, 1}); !r) return r.error();
    if (depth) {
      if (auto r = ctx->clear_depth(1.0); !r) return r.error();
      ctx->state().z_test = ctx->state().z_write = true;
      if (auto r = ctx->draw_indexed(v, near_first); !r) return r.error();
    } else {
      const std::vector<double> distance{0.25, 0.25, 0.75, 0.75};  // per triangle: the quads' z
      const auto order = far_to_near(near_first, distance);
      EXPECT_EQ(order, (std::vector<std::uint32_t>{4, 5, 6, 4, 6, 7, 0, 1, 2, 0, 2, 3})) << "back to front";
      if (auto r = ctx->draw_indexed(v, order); !r) return r.error();
    }
    if (auto r = ctx->swap(); !r) return r.error();
    auto img = ctx->read_display();
    if (!img) return img.error();
    if (const auto e = (*sink)->backend().device().errors()) return make_error("device errors: " + protocol::describe_errors(e));
    return img;
  };
  auto tested = render(true);
  ASSERT_TRUE(tested) << tested.error().message;
  auto painted = render(false);
  ASSERT_TRUE(painted) << painted.error().message;
  EXPECT_EQ(tested->rgba, painted->rgba);
  // and the overlap is there to be decided: both colours are visible, the near one where they overlap
  bool red = false, green = false;
  for (unsigned y = 0; y < 48; ++y)
    for (unsigned x = 0; x < 64; ++x) {
      red = red || tested->pixel(x, y)[0] == 255;
      green = green || tested->pixel(x, y)[1] == 255;
    }
  EXPECT_TRUE(red && green);
  EXPECT_EQ(tested->pixel(32, 24)[0], 255) << "(32, 24) lies in both quads: the near, red one covers it";
  EXPECT_EQ(tested->pixel(32, 24)[1], 0);
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
