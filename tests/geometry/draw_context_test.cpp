// The drawing API: what it sends (recorded), and what it draws (through the simulator when the
// tree has it). Expected values come from the API's documented conventions, not from its code.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <variant>

#include "gpubridge/draw/context.hpp"
#include "gpubridge/draw/sim_sink.hpp"

namespace gpubridge::draw {
namespace {

using protocol::Reg;
using geometry::Vec3;
using geometry::Vec4;

struct Write {
  Reg reg;
  std::uint64_t data;
};

std::vector<Write> writes_of(const protocol::CommandStream& s) {
  std::vector<Write> out;
  for (const auto& c : s.commands)
    if (const auto* f = std::get_if<protocol::FramesCmd>(&c.command))
      for (std::size_t i = 0; i < f->size(); ++i) out.push_back({static_cast<Reg>(f->view()[i].index), f->view()[i].data});
  return out;
}

std::vector<std::uint64_t> values(const std::vector<Write>& w, Reg r) {
  std::vector<std::uint64_t> out;
  for (const auto& x : w)
    if (x.reg == r) out.push_back(x.data);
  return out;
}

std::int64_t field(Reg r, const char* name, std::uint64_t data) { return protocol::describe(r).field(name)->get_signed(data); }

TEST(DrawContext, SetupPlacesBuffersAndSwapAlternates) {
  RecordingSink sink;
  auto ctx = Context::create(sink, {.width = 100, .height = 50, .format = protocol::PixelFormat::RGB565});
  ASSERT_TRUE(ctx) << ctx.error().message;
  // Colour buffers 100·50·2 = 10000 B → 10240 with 256-byte alignment; depth after both.
  auto w = writes_of(sink.stream());
  EXPECT_EQ(values(w, Reg::FB_DRAW), (std::vector<std::uint64_t>{0}));
  EXPECT_EQ(values(w, Reg::FB_Z), (std::vector<std::uint64_t>{20480}));
  ASSERT_EQ(values(w, Reg::FB_FORMAT).size(), 1u);
  EXPECT_EQ(field(Reg::FB_FORMAT, "WIDTH", values(w, Reg::FB_FORMAT)[0]), 100);
  EXPECT_EQ(values(w, Reg::SCISSOR).size(), 1u);
  ASSERT_TRUE(ctx->swap());
  ASSERT_TRUE(ctx->swap());
  w = writes_of(sink.stream());
  EXPECT_EQ(values(w, Reg::FB_DISPLAY), (std::vector<std::uint64_t>{0, 10240}));
  EXPECT_EQ(values(w, Reg::FB_DRAW), (std::vector<std::uint64_t>{0, 10240, 0}));
}

TEST(DrawContext, IndexedDrawTransformsThroughViewport) {
  RecordingSink sink;
  auto ctx = Context::create(sink, {.width = 64, .height = 32, .depth_buffer = false});
  ASSERT_TRUE(ctx);
  // Identity transform: NDC (-1, 1) is the top-left corner, (1, -1) the bottom-right.
  const Vertex v[] = {{{-1, 1, 0.5}, {1, 0, 0, 1}}, {{1, 1, 0.5}, {0, 1, 0, 1}}, {{-1, -1, 0.5}, {0, 0, 1, 1}}};
  const std::uint32_t idx[] = {0, 1, 2, 2, 1, 0};
  ASSERT_TRUE(ctx->draw_indexed(v, idx));
  ASSERT_TRUE(ctx->flush());
  const auto w = writes_of(sink.stream());
  const auto vert = values(w, Reg::VERTEX);
  ASSERT_EQ(vert.size(), 6u);
  EXPECT_EQ(field(Reg::VERTEX, "X", vert[0]), 0);
  EXPECT_EQ(field(Reg::VERTEX, "Y", vert[0]), 0);
  EXPECT_EQ(field(Reg::VERTEX, "X", vert[1]), 64 * 16);
  EXPECT_EQ(field(Reg::VERTEX, "Y", vert[2]), 32 * 16);
  EXPECT_EQ(field(Reg::VERTEX, "Z", vert[0]), 8388608);  // 0.5
  EXPECT_EQ(values(w, Reg::TRI_MODE).size(), 1u);
  EXPECT_EQ(values(w, Reg::PRIM), (std::vector<std::uint64_t>{0}));
  EXPECT_TRUE(values(w, Reg::TEXCOORD).empty());
}

TEST(DrawContext, BadInputIsAnError) {
  RecordingSink sink;
  auto ctx = Context::create(sink, {.width = 64, .height = 32, .depth_buffer = false});
  ASSERT_TRUE(ctx);
  const Vertex v[] = {{{0, 0, 0.5}}, {{1, 0, 0.5}}, {{0, 1, 0.5}}};
  const std::uint32_t bad_index[] = {0, 1, 3};
  auto r = ctx->draw_indexed(v, bad_index);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("index 3 at position 2 is out of range (3 vertices)"), std::string::npos);
  const std::uint32_t two[] = {0, 1};
  EXPECT_FALSE(ctx->draw_indexed(v, two));
  ctx->state().z_test = true;
  r = ctx->draw_indexed(v, std::vector<std::uint32_t>{0, 1, 2});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("no depth buffer"), std::string::npos);
  ctx->state().z_test = false;
  const Vertex nan[] = {{{std::nan(""), 0, 0.5}}, {{1, 0, 0.5}}, {{0, 1, 0.5}}};
  EXPECT_FALSE(ctx->draw_indexed(nan, std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_FALSE(ctx->clear({0, 0, std::nan(""), 1}));
  EXPECT_FALSE(ctx->clear_depth(1.0));  // no depth buffer
  Image odd;
  odd.width = 12;
  odd.height = 8;
  odd.rgba.assign(12 * 8 * 4, 0);
  EXPECT_FALSE(ctx->create_texture(odd));
  EXPECT_FALSE(sink.readback(0, 4));
}

TEST(DrawContext, VideoMemoryIsBounded) {
  RecordingSink sink(64 * 1024);
  auto too_big = Context::create(sink, {.width = 256, .height = 256});
  ASSERT_FALSE(too_big);
  EXPECT_NE(too_big.error().message.find("not enough video memory for the colour buffer (262144 bytes, 65536 bytes left"),
            std::string::npos)
      << too_big.error().message;
  RecordingSink small(64 * 1024);
  auto ctx = Context::create(small, {.width = 64, .height = 64, .depth_buffer = false, .double_buffer = false});
  ASSERT_TRUE(ctx);
  Image big;
  big.width = big.height = 256;
  big.rgba.assign(256 * 256 * 4, 0);
  auto t = ctx->create_texture(big);
  ASSERT_FALSE(t);
  EXPECT_NE(t.error().message.find("video memory full: 262144 bytes requested"), std::string::npos) << t.error().message;
}


// A unit cube with one colour per face, counter-clockwise when seen from outside.
void cube(std::vector<Vertex>& v, std::vector<std::uint32_t>& idx) {
  const Vec3 n[6] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
  const Vec4 c[6] = {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 1}, {1, 1, 0, 1}, {1, 0, 1, 1}, {0, 1, 1, 1}};
  for (int f = 0; f < 6; ++f) {
    // Two axes spanning the face, ordered so (a × b) = n (counter-clockwise from outside).
    Vec3 a = std::abs(n[f].x) > 0 ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
    Vec3 b = geometry::cross(n[f], a);
    const auto base = static_cast<std::uint32_t>(v.size());
    for (int k = 0; k < 4; ++k) {
      const double s = (k == 1 || k == 2) ? 1 : -1, t = (k >= 2) ? 1 : -1;
      v.push_back({n[f] + a * s + b * t, c[f], {s > 0 ? 1.0 : 0.0, t > 0 ? 1.0 : 0.0}});
    }
    // a × b = n by construction; order quad corners (-,-), (+,-), (+,+), (-,+) in (a, b).
    const bool ccw = geometry::dot(geometry::cross(a, b), n[f]) > 0;
    static constexpr std::uint32_t kCcw[6] = {0, 1, 2, 0, 2, 3}, kCw[6] = {0, 2, 1, 0, 3, 2};
    for (std::uint32_t k : ccw ? kCcw : kCw) idx.push_back(base + k);
  }
}

TEST(DrawOnSimulator, CubeWithDepthAndCulling) {
  auto sink = SimulatorSink::create();
  ASSERT_TRUE(sink);
  auto ctx = Context::create(**sink, {.width = 96, .height = 96});
  ASSERT_TRUE(ctx);
  std::vector<Vertex> v;
  std::vector<std::uint32_t> idx;
  cube(v, idx);
  ASSERT_TRUE(ctx->clear({0, 0, 0, 1}));
  ASSERT_TRUE(ctx->clear_depth(1.0));
  ctx->state().z_test = ctx->state().z_write = true;
  ctx->state().gouraud = false;
  const auto proj = geometry::perspective(std::numbers::pi / 3, 1.0, 0.5, 20);
  const auto view = geometry::look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0});
  ctx->set_transform(proj * view);
  ASSERT_TRUE(ctx->draw_indexed(v, idx));
  ASSERT_TRUE(ctx->swap());
  auto img = ctx->read_display();
  ASSERT_TRUE(img) << img.error().message;
  // Looking down -z at the cube: the +z face (red) fills the centre; corners show the clear colour.
  EXPECT_EQ(img->pixel(48, 48)[0], 255);
  EXPECT_EQ(img->pixel(48, 48)[1], 0);
  EXPECT_EQ(img->pixel(1, 1)[0], 0);
  EXPECT_EQ(img->pixel(1, 1)[3], 255);
  // The same picture was scanned out by the swap.
  const auto frame = (*sink)->latest_frame();
  ASSERT_TRUE(frame);
  EXPECT_EQ(image_from_device(frame->format, frame->width, frame->height, frame->pixels), *img);
  // Back-face culling gives the same picture with fewer triangles sent.
  const auto drawn = ctx->stats().emitted;
  ctx->set_cull(geometry::CullMode::Back);
  ASSERT_TRUE(ctx->clear({0, 0, 0, 1}));
  ASSERT_TRUE(ctx->clear_depth(1.0));
  ASSERT_TRUE(ctx->draw_indexed(v, idx));
  ASSERT_TRUE(ctx->swap());
  auto culled = ctx->read_display();
  ASSERT_TRUE(culled);
  EXPECT_EQ(*culled, *img);
  EXPECT_LT(ctx->stats().emitted - drawn, drawn);
  EXPECT_EQ((*sink)->backend().device().errors(), 0);
}

TEST(DrawOnSimulator, CameraInsideGeometryIsNearClipped) {
  // A floor quad stretching from behind the camera to far ahead: without near clipping its
  // behind-the-eye corners would project to nonsense; clipped, the lower half of the screen is
  // floor and the upper half the clear colour.
  auto sink = SimulatorSink::create();
  ASSERT_TRUE(sink);
  auto ctx = Context::create(**sink, {.width = 64, .height = 64, .depth_buffer = false});
  ASSERT_TRUE(ctx);
  ASSERT_TRUE(ctx->clear({0, 0, 0, 1}));
  ctx->set_transform(geometry::perspective(std::numbers::pi / 2, 1.0, 0.1, 100) *
                     geometry::look_at({0, 1, 0}, {0, 1, -1}, {0, 1, 0}));
  const Vertex floor[] = {{{-50, 0, 50}, {0, 1, 0, 1}}, {{50, 0, 50}, {0, 1, 0, 1}}, {{50, 0, -50}, {0, 1, 0, 1}},
                          {{-50, 0, -50}, {0, 1, 0, 1}}};
  ASSERT_TRUE(ctx->draw_indexed(floor, std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
  ASSERT_TRUE(ctx->swap());
  EXPECT_GT(ctx->stats().clipped, 0u);
  auto img = ctx->read_display();
  ASSERT_TRUE(img);
  for (unsigned x = 0; x < 64; x += 7) {
    EXPECT_EQ(img->pixel(x, 63)[1], 255) << x;  // bottom row: floor
    EXPECT_EQ(img->pixel(x, 20)[1], 0) << x;    // above the horizon (far plane at 100 ⇒ horizon ≈ row 32)
  }
}

TEST(DrawOnSimulator, TexturedQuadSamplesTheUploadedTexture) {
  auto sink = SimulatorSink::create();
  ASSERT_TRUE(sink);
  auto ctx = Context::create(**sink, {.width = 32, .height = 32, .depth_buffer = false});
  ASSERT_TRUE(ctx);
  Image tex;
  tex.width = tex.height = 8;
  tex.rgba.resize(8 * 8 * 4);
  for (unsigned y = 0; y < 8; ++y)
    for (unsigned x = 0; x < 8; ++x) {
      auto* p = tex.pixel(x, y);
      p[0] = static_cast<std::uint8_t>(x * 32);
      p[1] = static_cast<std::uint8_t>(y * 32);
      p[2] = 7;
      p[3] = 255;
    }
  auto t = ctx->create_texture(tex);
  ASSERT_TRUE(t);
  ASSERT_TRUE(ctx->bind_texture(*t));
  ctx->state().tex_decal = true;
  // Screen-space quad covering the framebuffer, u/v 0..1: each texel covers a 4x4 pixel block.
  std::vector<geometry::ScreenVertex> q(6);
  const double xy[6][2] = {{0, 0}, {32, 0}, {32, 32}, {0, 0}, {32, 32}, {0, 32}};
  for (int i = 0; i < 6; ++i) q[i] = {xy[i][0], xy[i][1], 0, 1, {1, 1, 1, 1}, {xy[i][0] / 32, xy[i][1] / 32}};
  ASSERT_TRUE(ctx->draw_screen(q));
  ASSERT_TRUE(ctx->swap());
  auto img = ctx->read_display();
  ASSERT_TRUE(img);
  for (unsigned y = 1; y < 32; y += 4)
    for (unsigned x = 1; x < 32; x += 4) {
      EXPECT_EQ(img->pixel(x, y)[0], (x / 4) * 32) << x << "," << y;
      EXPECT_EQ(img->pixel(x, y)[1], (y / 4) * 32) << x << "," << y;
      EXPECT_EQ(img->pixel(x, y)[2], 7);
    }
}


}  // namespace
}  // namespace gpubridge::draw
