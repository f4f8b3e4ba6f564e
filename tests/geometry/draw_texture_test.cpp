// Texture lifetime in the drawing API: release and reuse of video memory, the bound texture
// after a release, stale handles, in-place updates (rendered through the simulator), and the
// error when video memory is full. Addresses are derived from the documented layout: buffers
// first, then 256-byte-aligned first-fit texture blocks.
#include <gtest/gtest.h>

#include <variant>

#include "gpubridge/draw/context.hpp"
#include "gpubridge/draw/sim_sink.hpp"

namespace gpubridge::draw {
namespace {

using protocol::Reg;

Image solid(unsigned w, unsigned h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.resize(std::size_t{w} * h * 4);
  for (std::size_t i = 0; i < img.rgba.size(); i += 4) {
    img.rgba[i] = r;
    img.rgba[i + 1] = g;
    img.rgba[i + 2] = b;
    img.rgba[i + 3] = 255;
  }
  return img;
}

std::vector<std::uint32_t> upload_addresses(const protocol::CommandStream& s) {
  std::vector<std::uint32_t> out;
  for (const auto& c : s.commands)
    if (const auto* u = std::get_if<protocol::UploadCmd>(&c.command)) out.push_back(u->address);
  return out;
}

// The data of every write of `reg`, in order.
std::vector<std::uint64_t> writes(const protocol::CommandStream& s, Reg reg) {
  std::vector<std::uint64_t> out;
  for (const auto& c : s.commands)
    if (const auto* f = std::get_if<protocol::FramesCmd>(&c.command))
      for (std::size_t i = 0; i < f->size(); ++i)
        if (static_cast<Reg>(f->view()[i].index) == reg) out.push_back(f->view()[i].data);
  return out;
}
std::size_t count_writes(const protocol::CommandStream& s, Reg reg) { return writes(s, reg).size(); }

// 64x32 RGBA8888, single-buffered, no depth: the colour buffer is 8192 bytes at 0, textures follow.
constexpr ContextOptions kSmall{.width = 64, .height = 32, .depth_buffer = false, .double_buffer = false};
constexpr std::uint32_t kFirstTexture = 64 * 32 * 4;

TEST(DrawTextures, WithoutReleasesTexturesFollowTheBuffersInCreationOrder) {
  RecordingSink sink;
  auto ctx = Context::create(sink, {.width = 100, .height = 50, .format = protocol::PixelFormat::RGB565});
  ASSERT_TRUE(ctx);
  // Colour 2 × 10000 B → 2 × 10240; depth 20000 B → 20224; then 8x8 RGBA8888 (256 B), 16x16 RGB565 (512 B).
  auto a = ctx->create_texture(solid(8, 8, 1, 2, 3));
  auto b = ctx->create_texture(solid(16, 16, 1, 2, 3), {.format = protocol::PixelFormat::RGB565});
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->address, 2u * 10240 + 20224);
  EXPECT_EQ(b->address, 2u * 10240 + 20224 + 256);
  EXPECT_NE(a->id, b->id);
  EXPECT_EQ(upload_addresses(sink.stream()), (std::vector<std::uint32_t>{a->address, b->address}));
}

TEST(DrawTextures, ReleaseThenCreateReusesTheAddress) {
  RecordingSink sink;
  auto ctx = Context::create(sink, kSmall);
  ASSERT_TRUE(ctx);
  auto a = ctx->create_texture(solid(16, 16, 9, 9, 9));
  auto b = ctx->create_texture(solid(16, 16, 9, 9, 9));
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->address, kFirstTexture);
  const std::uint32_t a_address = a->address;
  EXPECT_TRUE(ctx->release_texture(*a));
  EXPECT_EQ(a->id, 0u);  // the handle is cleared
  EXPECT_EQ(ctx->live_textures(), 1u);
  auto c = ctx->create_texture(solid(8, 8, 9, 9, 9));
  ASSERT_TRUE(c);
  EXPECT_EQ(c->address, a_address);
  EXPECT_EQ(upload_addresses(sink.stream()).back(), a_address);
}

TEST(DrawTextures, StreamingManyTexturesNeverRunsOutWhenEachIsReleased) {
  // Room for the colour buffer and only three 64x64 RGBA textures (16 KiB each).
  RecordingSink sink(kFirstTexture + 3 * 16384);
  auto ctx = Context::create(sink, kSmall);
  ASSERT_TRUE(ctx);
  auto previous = ctx->create_texture(solid(64, 64, 0, 0, 0));
  ASSERT_TRUE(previous);
  for (int frame = 1; frame < 200; ++frame) {
    auto next = ctx->create_texture(solid(64, 64, static_cast<std::uint8_t>(frame), 0, 0));
    ASSERT_TRUE(next) << "frame " << frame << ": " << next.error().message;
    ASSERT_TRUE(ctx->bind_texture(*next));
    EXPECT_TRUE(ctx->release_texture(*previous));
    previous = *next;
  }
  EXPECT_EQ(ctx->live_textures(), 1u);
  EXPECT_EQ(ctx->video_memory().free_bytes(), 2u * 16384);
}

TEST(DrawTextures, FullVideoMemoryNamesTheSizes) {
  RecordingSink sink(kFirstTexture + 3 * 16384);
  auto ctx = Context::create(sink, kSmall);
  ASSERT_TRUE(ctx);
  auto a = ctx->create_texture(solid(64, 64, 1, 1, 1));
  auto b = ctx->create_texture(solid(64, 64, 1, 1, 1));
  auto c = ctx->create_texture(solid(64, 64, 1, 1, 1));
  ASSERT_TRUE(a && b && c);
  ASSERT_TRUE(ctx->release_texture(*b));
  // 16 KiB free (b's hole); a 128x64 texture needs 32 KiB.
  auto big = ctx->create_texture(solid(128, 64, 1, 1, 1));
  ASSERT_FALSE(big);
  EXPECT_NE(big.error().message.find("video memory full: 32768 bytes requested, largest free block 16384 bytes"),
            std::string::npos)
      << big.error().message;
  EXPECT_NE(big.error().message.find("release textures or use a smaller format"), std::string::npos);
  // The suggested remedy works: the same image in RGB565 is 16 KiB.
  auto small = ctx->create_texture(solid(128, 64, 1, 1, 1), {.format = protocol::PixelFormat::RGB565});
  ASSERT_TRUE(small) << small.error().message;
}

TEST(DrawTextures, DoubleReleaseAndReleasingCopiesAreSafe) {
  RecordingSink sink;
  auto ctx = Context::create(sink, kSmall);
  ASSERT_TRUE(ctx);
  auto a = ctx->create_texture(solid(8, 8, 1, 1, 1));
  auto b = ctx->create_texture(solid(8, 8, 1, 1, 1));
  ASSERT_TRUE(a && b);
  Texture copy = *a;
  EXPECT_TRUE(ctx->release_texture(*a));
  EXPECT_FALSE(ctx->release_texture(*a));   // cleared handle
  EXPECT_FALSE(ctx->release_texture(copy));  // stale copy: must not free a's block a second time
  // A texture created in the freed block is not freed by the stale copy either.
  auto c = ctx->create_texture(solid(8, 8, 1, 1, 1));
  ASSERT_TRUE(c);
  EXPECT_EQ(c->address, kFirstTexture);
  Texture stale = Texture{};
  stale.address = c->address;
  stale.id = 1;  // a's old id
  EXPECT_FALSE(ctx->release_texture(stale));
  EXPECT_EQ(ctx->live_textures(), 2u);
  EXPECT_EQ(ctx->video_memory().block_size(c->address), 256u);
}

TEST(DrawTextures, ReleasingTheBoundTextureUnbindsIt) {
  RecordingSink sink;
  auto ctx = Context::create(sink, kSmall);
  ASSERT_TRUE(ctx);
  auto t = ctx->create_texture(solid(8, 8, 1, 1, 1));
  ASSERT_TRUE(t);
  ASSERT_TRUE(ctx->bind_texture(*t));
  std::vector<geometry::ScreenVertex> tri(3);
  tri[0] = {0, 0, 0, 1, {1, 1, 1, 1}, {0, 0}};
  tri[1] = {16, 0, 0, 1, {1, 1, 1, 1}, {1, 0}};
  tri[2] = {0, 16, 0, 1, {1, 1, 1, 1}, {0, 1}};
  ASSERT_TRUE(ctx->draw_screen(tri));
  ASSERT_TRUE(ctx->flush());
  EXPECT_EQ(count_writes(sink.stream(), Reg::TEXCOORD), 3u);
  ASSERT_TRUE(ctx->release_texture(*t));
  ASSERT_TRUE(ctx->draw_screen(tri));  // untextured now: no texture coordinates are sent
  ASSERT_TRUE(ctx->flush());
  EXPECT_EQ(count_writes(sink.stream(), Reg::TEXCOORD), 3u);
  EXPECT_EQ(count_writes(sink.stream(), Reg::VERTEX), 6u);
}

TEST(DrawTextures, BindingAStaleOrEditedHandleFailsAtOnceAndKeepsTheBinding) {
  RecordingSink sink;
  auto ctx = Context::create(sink, kSmall);
  ASSERT_TRUE(ctx);
  auto a = ctx->create_texture(solid(8, 8, 1, 1, 1));
  auto b = ctx->create_texture(solid(8, 8, 2, 2, 2));
  ASSERT_TRUE(a && b);
  ASSERT_TRUE(ctx->bind_texture(*a));
  const Texture released = *b;
  ASSERT_TRUE(ctx->release_texture(*b));
  auto r = ctx->bind_texture(released);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("bind_texture: texture 2 (address 0x"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("was released"), std::string::npos);
  // A live id with a size edited by hand would sample memory outside the texture: rejected too.
  Texture edited = *a;
  edited.format.width = 1024;
  EXPECT_FALSE(ctx->bind_texture(edited));
  EXPECT_FALSE(ctx->update_texture(edited, solid(1024, 8, 0, 0, 0)));
  // Neither failure changed the binding: the draw samples `a`.
  std::vector<geometry::ScreenVertex> tri(3);
  tri[1].x = 16;
  tri[2].y = 16;
  ASSERT_TRUE(ctx->draw_screen(tri));
  ASSERT_TRUE(ctx->flush());
  const auto base = writes(sink.stream(), Reg::TEX_BASE);
  ASSERT_EQ(base.size(), 1u);
  EXPECT_EQ(base[0], a->address);
  ctx->unbind_texture();
  ASSERT_TRUE(ctx->draw_screen(tri));
  ASSERT_TRUE(ctx->flush());
  EXPECT_EQ(count_writes(sink.stream(), Reg::TEXCOORD), 3u);  // the second draw is untextured
}

TEST(DrawTextures, UpdateRejectsOtherSizesAndReleasedTextures) {
  RecordingSink sink;
  auto ctx = Context::create(sink, kSmall);
  ASSERT_TRUE(ctx);
  auto t = ctx->create_texture(solid(16, 8, 1, 1, 1), {.format = protocol::PixelFormat::RGB565});
  ASSERT_TRUE(t);
  auto r = ctx->update_texture(*t, solid(8, 16, 1, 1, 1));
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("the image is 8x16 but the texture is 16x8"), std::string::npos) << r.error().message;
  Image broken = solid(16, 8, 1, 1, 1);
  broken.rgba.pop_back();
  EXPECT_FALSE(ctx->update_texture(*t, broken));
  ASSERT_TRUE(ctx->update_texture(*t, solid(16, 8, 1, 1, 1)));
  // In place, converted to the texture's format (16·8·2 bytes of RGB565).
  const auto& cmds = sink.stream().commands;
  const auto* u = std::get_if<protocol::UploadCmd>(&cmds.back().command);
  ASSERT_NE(u, nullptr);
  EXPECT_EQ(u->address, t->address);
  EXPECT_EQ(u->data.size(), 16u * 8 * 2);
  Texture copy = *t;
  ASSERT_TRUE(ctx->release_texture(*t));
  r = ctx->update_texture(copy, solid(16, 8, 1, 1, 1));
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("was released"), std::string::npos);
}


// A textured quad covering the whole 32x32 framebuffer (decal: the texel colour alone).
Result<Image> draw_textured_quad(Context& ctx, const Texture& t, bool swap_and_read = true) {
  if (auto r = ctx.bind_texture(t); !r) return r.error();
  ctx.state().tex_decal = true;
  std::vector<geometry::ScreenVertex> q(6);
  const double xy[6][2] = {{0, 0}, {32, 0}, {32, 32}, {0, 0}, {32, 32}, {0, 32}};
  for (int i = 0; i < 6; ++i) q[i] = {xy[i][0], xy[i][1], 0, 1, {1, 1, 1, 1}, {xy[i][0] / 32, xy[i][1] / 32}};
  if (auto r = ctx.draw_screen(q); !r) return r.error();
  if (!swap_and_read) return Image{};
  if (auto r = ctx.swap(); !r) return r.error();
  return ctx.read_display();
}

void expect_all(const Image& img, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  for (unsigned y = 0; y < img.height; y += 5)
    for (unsigned x = 0; x < img.width; x += 5) {
      ASSERT_EQ(img.pixel(x, y)[0], r) << x << "," << y;
      ASSERT_EQ(img.pixel(x, y)[1], g) << x << "," << y;
      ASSERT_EQ(img.pixel(x, y)[2], b) << x << "," << y;
    }
}

TEST(DrawTexturesOnSimulator, UpdateTextureRendersTheNewContents) {
  auto sink = SimulatorSink::create();
  ASSERT_TRUE(sink);
  auto ctx = Context::create(**sink, {.width = 32, .height = 32, .depth_buffer = false});
  ASSERT_TRUE(ctx);
  auto t = ctx->create_texture(solid(8, 8, 255, 0, 0));
  ASSERT_TRUE(t);
  auto first = draw_textured_quad(*ctx, *t);
  ASSERT_TRUE(first) << first.error().message;
  expect_all(*first, 255, 0, 0);
  ASSERT_TRUE(ctx->update_texture(*t, solid(8, 8, 0, 0, 255)));
  auto second = draw_textured_quad(*ctx, *t);
  ASSERT_TRUE(second) << second.error().message;
  expect_all(*second, 0, 0, 255);
  EXPECT_EQ((*sink)->backend().device().errors(), 0);
}

TEST(DrawTexturesOnSimulator, DrawsBeforeAnUpdateOrReleaseSampleTheOldContents) {
  auto sink = SimulatorSink::create();
  ASSERT_TRUE(sink);
  auto ctx = Context::create(**sink, {.width = 32, .height = 32, .depth_buffer = false, .double_buffer = false});
  ASSERT_TRUE(ctx);
  auto t = ctx->create_texture(solid(8, 8, 0, 255, 0));
  ASSERT_TRUE(t);
  // Drawn (still pending in the context), then the texture changes: the draw must see green.
  ASSERT_TRUE(draw_textured_quad(*ctx, *t, false));
  ASSERT_TRUE(ctx->update_texture(*t, solid(8, 8, 255, 0, 255)));
  ASSERT_TRUE(ctx->swap());
  auto img = ctx->read_display();
  ASSERT_TRUE(img);
  expect_all(*img, 0, 255, 0);
  // Same for a release followed by a new texture in the freed block.
  ASSERT_TRUE(draw_textured_quad(*ctx, *t, false));
  const std::uint32_t old_address = t->address;
  ASSERT_TRUE(ctx->release_texture(*t));
  auto other = ctx->create_texture(solid(8, 8, 255, 255, 0));
  ASSERT_TRUE(other);
  EXPECT_EQ(other->address, old_address);
  ASSERT_TRUE(ctx->swap());
  img = ctx->read_display();
  ASSERT_TRUE(img);
  expect_all(*img, 255, 0, 255);
  // And the new texture, drawn now, shows its own contents.
  auto last = draw_textured_quad(*ctx, *other);
  ASSERT_TRUE(last);
  expect_all(*last, 255, 255, 0);
}


}  // namespace
}  // namespace gpubridge::draw
