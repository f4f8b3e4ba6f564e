// The texture unit's row-pair shadow (backends/sim/src/texture_shadow.hpp): its entries against
// the linear texture, and that it is dropped whenever a byte under its texture is written (MEM_DATA,
// the writable memory view, a clear, a draw into the texture), so a draw after the write samples
// the new texels: compared with a device that had those texels from the start.
#include <gtest/gtest.h>

#include <cstring>

#include "sim_test_util.hpp"
#include "texture_shadow.hpp"
#include "video_memory.hpp"

namespace gpubridge::sim::test {
namespace {

using namespace protocol;

constexpr std::uint32_t kTexBase = 0x200000;
constexpr unsigned kLog2W = 5, kLog2H = 4, kW = 1u << kLog2W, kH = 1u << kLog2H;

std::array<std::uint8_t, 4> pattern(unsigned i, unsigned j, unsigned seed) {
  return {static_cast<std::uint8_t>(i * 8 + seed), static_cast<std::uint8_t>(j * 16 + 3 * seed),
          static_cast<std::uint8_t>((i ^ j) * 5 + seed), static_cast<std::uint8_t>(255 - i * j - seed)};
}

DrawState textured_state(std::uint32_t fb_draw, PixelFormat format = PixelFormat::RGBA8888) {
  DrawState st;
  st.textured = true;
  st.tex.base = kTexBase;
  st.tex.wl = kLog2W;
  st.tex.hl = kLog2H;
  st.tex.format = format;
  st.tex.bilinear = true;
  st.tex.in_vram = true;
  st.fb_draw = fb_draw;
  st.fb_width = 16;
  st.fb_height = 16;
  st.bpp = 4;
  return st;
}

std::uint32_t word_of(std::uint8_t r, std::uint8_t g, std::uint8_t b, std::uint8_t a) {
  return std::uint32_t{r} | (std::uint32_t{g} << 8) | (std::uint32_t{b} << 16) | (std::uint32_t{a} << 24);
}

TEST(SimTextureShadow, EntriesPairEachRowWithTheNextModuloHeight) {
  VideoMemory mem(4u << 20);
  for (unsigned j = 0; j < kH; ++j)
    for (unsigned i = 0; i < kW; ++i) {
      const auto c = pattern(i, j, 1);
      std::memcpy(mem.data() + kTexBase + (j * kW + i) * 4, c.data(), 4);
    }
  const DrawState st = textured_state(0);
  TextureShadows& sh = mem.shadows();
  EXPECT_EQ(sh.find(st.tex), nullptr);
  ASSERT_TRUE(sh.outdated(st, false));
  sh.update(st, mem.data(), false);
  const std::uint64_t* e = sh.find(st.tex);
  ASSERT_NE(e, nullptr);
  EXPECT_FALSE(sh.outdated(st, false));
  for (unsigned j = 0; j < kH; ++j)
    for (unsigned i = 0; i < kW; ++i) {
      const auto lo = pattern(i, j, 1), hi = pattern(i, (j + 1) % kH, 1);
      const std::uint64_t expect =
          word_of(lo[0], lo[1], lo[2], lo[3]) | (std::uint64_t{word_of(hi[0], hi[1], hi[2], hi[3])} << 32);
      ASSERT_EQ(e[j * kW + i], expect) << i << "," << j;
    }
}

TEST(SimTextureShadow, PackedFormatsAreExpandedToColourWords) {
  VideoMemory mem(4u << 20);
  auto v565 = [](unsigned i, unsigned j) { return static_cast<std::uint16_t>(i * 2113u + j * 977u + 5u); };
  for (unsigned j = 0; j < kH; ++j)
    for (unsigned i = 0; i < kW; ++i) {
      const std::uint16_t v = v565(i, j);
      mem.data()[kTexBase + (j * kW + i) * 2] = static_cast<std::uint8_t>(v >> 8);  // big-endian (section 4)
      mem.data()[kTexBase + (j * kW + i) * 2 + 1] = static_cast<std::uint8_t>(v);
    }
  const DrawState st = textured_state(0, PixelFormat::RGB565);
  mem.shadows().update(st, mem.data(), false);
  const std::uint64_t* e = mem.shadows().find(st.tex);
  ASSERT_NE(e, nullptr);
  auto expand = [](unsigned v) {  // bit replication, written out here
    const unsigned r = v >> 11, g = (v >> 5) & 63, b = v & 31;
    return word_of(static_cast<std::uint8_t>(r << 3 | r >> 2), static_cast<std::uint8_t>(g << 2 | g >> 4),
                   static_cast<std::uint8_t>(b << 3 | b >> 2), 255);
  };
  for (unsigned j = 0; j < kH; ++j)
    for (unsigned i = 0; i < kW; ++i)
      ASSERT_EQ(e[j * kW + i], expand(v565(i, j)) | (std::uint64_t{expand(v565(i, (j + 1) % kH))} << 32)) << i << "," << j;
}

TEST(SimTextureShadow, WritesUnderTheTextureDropIt) {
  VideoMemory mem(4u << 20);
  const DrawState st = textured_state(0);
  const std::uint64_t tex_bytes = std::uint64_t{kW} * kH * 4;
  const std::uint8_t b[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  auto rebuild = [&] {
    mem.shadows().update(st, mem.data(), false);
    ASSERT_NE(mem.shadows().find(st.tex), nullptr);
  };
  rebuild();
  mem.write(kTexBase - 8, b, 8);  // ends just before the texture
  mem.write(kTexBase + tex_bytes, b, 8);  // starts just after it
  EXPECT_NE(mem.shadows().find(st.tex), nullptr);
  mem.write(kTexBase - 4, b, 8);  // its first texel
  EXPECT_EQ(mem.shadows().find(st.tex), nullptr);
  rebuild();
  mem.write(kTexBase + tex_bytes - 1, b, 1);  // its last byte
  EXPECT_EQ(mem.shadows().find(st.tex), nullptr);
  rebuild();
  (void)static_cast<const VideoMemory&>(mem).span();  // reading keeps it
  EXPECT_NE(mem.shadows().find(st.tex), nullptr);
  (void)mem.span();  // the writable view may write anywhere
  EXPECT_EQ(mem.shadows().find(st.tex), nullptr);
  rebuild();
  // A draw whose colour buffer covers a texel drops the shadow; its own texture is not shadowed.
  const DrawState into = textured_state(kTexBase + tex_bytes - 16 * 16 * 4 + 4);
  EXPECT_TRUE(mem.shadows().outdated(into, false));
  mem.shadows().update(into, mem.data(), false);
  EXPECT_EQ(mem.shadows().find(st.tex), nullptr);
  EXPECT_FALSE(TextureShadows::wanted(into, false));
  EXPECT_FALSE(mem.shadows().outdated(into, false));
  // The same through the depth buffer, only when the draw writes Z.
  rebuild();
  DrawState z = textured_state(0);
  z.fb_z = kTexBase;
  z.z_test = true;
  EXPECT_FALSE(mem.shadows().outdated(z, false));
  z.z_write = true;
  EXPECT_TRUE(mem.shadows().outdated(z, false));
  EXPECT_FALSE(TextureShadows::wanted(z, false));
}

TEST(SimTextureShadow, OnlyBilinearTexturesInsideMemoryAreShadowed) {
  DrawState st = textured_state(0);
  EXPECT_TRUE(TextureShadows::wanted(st, false));
  st.tex.bilinear = false;
  EXPECT_FALSE(TextureShadows::wanted(st, false));
  st = textured_state(0);
  st.tex.in_vram = false;
  EXPECT_FALSE(TextureShadows::wanted(st, false));
  st = textured_state(0);
  st.textured = false;
  EXPECT_FALSE(TextureShadows::wanted(st, false));
  st = textured_state(0);
  st.preview_plain = true;  // decided for every state; only `--accuracy preview` draws with it
  EXPECT_TRUE(TextureShadows::wanted(st, false));
  EXPECT_FALSE(TextureShadows::wanted(st, true));
}

// A device drawing perspective-textured, bilinear triangles over a 32 x 32 canvas from a
// 32 x 16 texture at kTexBase.
struct TexturedCanvas {
  static constexpr unsigned kSide = 32;
  std::unique_ptr<Device> dev;
  explicit TexturedCanvas(unsigned threads) {
    DeviceOptions o;
    o.threads = threads;
    dev = make_device(o);
    w(*dev, Reg::FB_FORMAT, fb_format(kSide, kSide));
    w(*dev, Reg::FB_DRAW, 0);
    w(*dev, Reg::TEX_BASE, kTexBase);
    w(*dev, Reg::TEX_FMT, (std::uint64_t{1} << 12) | (kLog2H << 4) | kLog2W);  // bilinear, REPEAT
  }
  void upload(unsigned seed) {
    auto mem = dev->memory();
    for (unsigned j = 0; j < kH; ++j)
      for (unsigned i = 0; i < kW; ++i) {
        const auto c = pattern(i, j, seed);
        std::copy(c.begin(), c.end(), mem.begin() + kTexBase + (j * kW + i) * 4);
      }
  }
  void clear() {
    w(*dev, Reg::CLEAR_COLOR, 0);
    w(*dev, Reg::CLEAR, 0);
  }
  // Two triangles over the canvas, texture coordinates from -0.4 to 1.6 with Q from 1 to 0.3.
  void draw_textured() {
    w(*dev, Reg::TRI_MODE, 2u | (1u << 14));  // textured, decal
    w(*dev, Reg::PRIM, 0);
    struct V {
      int x, y;
      double u, v, q;
    };
    const V c[4] = {{0, 0, -0.4, -0.4, 1.0}, {kSide * 16, 0, 1.6, -0.4, 0.3}, {kSide * 16, kSide * 16, 1.6, 1.6, 0.3},
                    {0, kSide * 16, -0.4, 1.6, 1.0}};
    for (int k : {0, 1, 2, 0, 2, 3}) {
      const double q = c[k].q;
      const auto s = static_cast<std::int32_t>(c[k].u * q * (1 << 24)), t = static_cast<std::int32_t>(c[k].v * q * (1 << 24));
      w(*dev, Reg::COLOR, color(0xFFFFFFFF, static_cast<std::uint32_t>(q * 4294967295.0)));
      w(*dev, Reg::TEXCOORD, (std::uint64_t{static_cast<std::uint32_t>(s)} << 32) | static_cast<std::uint32_t>(t));
      w(*dev, Reg::VERTEX, vtx(c[k].x, c[k].y));
    }
  }
  std::vector<std::uint8_t> canvas() const {
    dev->drain();
    const auto m = static_cast<const Device&>(*dev).memory();
    return {m.begin(), m.begin() + kSide * kSide * 4};
  }
  std::vector<std::uint8_t> texture() const {
    const auto m = static_cast<const Device&>(*dev).memory();
    return {m.begin() + kTexBase, m.begin() + kTexBase + kW * kH * 4};
  }
};

// What a fresh device draws from `texels`.
std::vector<std::uint8_t> drawn_from(const std::vector<std::uint8_t>& texels, unsigned threads) {
  TexturedCanvas f(threads);
  auto mem = f.dev->memory();
  std::copy(texels.begin(), texels.end(), mem.begin() + kTexBase);
  f.draw_textured();
  return f.canvas();
}

TEST(SimTextureShadow, MemDataAfterADrawIsSampled) {
  for (unsigned threads : {1u, 2u}) {
    TexturedCanvas a(threads);
    a.upload(1);
    a.draw_textured();
    const auto first = a.canvas();
    // Rewrite the texture through MEM_ADDR / MEM_DATA (section 2.4: big-endian words).
    w(*a.dev, Reg::MEM_ADDR, kTexBase);
    for (unsigned k = 0; k < kW * kH / 2; ++k) {
      const unsigned i = (2 * k) % kW, j = (2 * k) / kW;
      const auto c0 = pattern(i, j, 9), c1 = pattern(i + 1, j, 9);
      std::uint64_t data = 0;
      for (int b = 0; b < 4; ++b) data = (data << 8) | c0[b];
      for (int b = 0; b < 4; ++b) data = (data << 8) | c1[b];
      w(*a.dev, Reg::MEM_DATA, data);
    }
    a.clear();
    a.draw_textured();
    TexturedCanvas ref(threads);
    ref.upload(9);
    ASSERT_EQ(a.texture(), ref.texture());
    const auto second = a.canvas();
    EXPECT_NE(second, first);  // the new texels show
    EXPECT_EQ(second, drawn_from(ref.texture(), threads)) << threads << " threads";
  }
}

TEST(SimTextureShadow, WritableMemoryViewAfterADrawIsSampled) {
  for (unsigned threads : {1u, 2u}) {
    TexturedCanvas a(threads);
    a.upload(1);
    a.draw_textured();
    const auto first = a.canvas();
    a.upload(4);
    a.clear();
    a.draw_textured();
    const auto second = a.canvas();
    EXPECT_NE(second, first);
    EXPECT_EQ(second, drawn_from(a.texture(), threads)) << threads << " threads";
  }
}

TEST(SimTextureShadow, ClearOverTheTextureIsSampled) {
  for (unsigned threads : {1u, 2u}) {
    TexturedCanvas a(threads);
    a.upload(1);
    a.draw_textured();
    const auto first = a.canvas();
    // A clear of a 32-pixel-wide target at the texture's rows 4-5 (scissor rows 4..5 of it).
    w(*a.dev, Reg::FB_DRAW, kTexBase);
    w(*a.dev, Reg::SCISSOR, scissor(0, 4, kW, 6));
    w(*a.dev, Reg::CLEAR_COLOR, 0x11223344);
    w(*a.dev, Reg::CLEAR, 0);
    w(*a.dev, Reg::FB_DRAW, 0);
    w(*a.dev, Reg::SCISSOR, scissor(0, 0, 1024, 1024));
    a.clear();
    a.draw_textured();
    const auto second = a.canvas();
    EXPECT_NE(second, first);
    EXPECT_EQ(second, drawn_from(a.texture(), threads)) << threads << " threads";
  }
}

TEST(SimTextureShadow, DrawIntoTheTextureIsSampled) {
  for (unsigned threads : {1u, 2u}) {
    TexturedCanvas a(threads);
    a.upload(1);
    a.draw_textured();
    const auto first = a.canvas();
    // An untextured triangle drawn with the texture as the colour buffer (32 texels a row).
    w(*a.dev, Reg::FB_DRAW, kTexBase);
    w(*a.dev, Reg::TRI_MODE, 0);
    w(*a.dev, Reg::PRIM, 0);
    w(*a.dev, Reg::COLOR, color(0x80FF20C0));
    w(*a.dev, Reg::VERTEX, vtx(2 * 16, 1 * 16));
    w(*a.dev, Reg::VERTEX, vtx(30 * 16, 3 * 16));
    w(*a.dev, Reg::VERTEX, vtx(6 * 16, 15 * 16));
    w(*a.dev, Reg::FB_DRAW, 0);
    a.clear();
    a.draw_textured();
    const auto second = a.canvas();
    EXPECT_NE(second, first);
    EXPECT_EQ(second, drawn_from(a.texture(), threads)) << threads << " threads";
  }
}

}  // namespace
}  // namespace gpubridge::sim::test
