// Scene → command stream: setup registers, memory layout, uploads in the device format,
// triangles through the geometry pipeline, and errors that point at the triangle.
#include <gtest/gtest.h>

#include <variant>

#include <nlohmann/json.hpp>

#include "gpubridge/scene/scene.hpp"

namespace gpubridge::scene {
namespace {

using protocol::Reg;

struct Write {
  Reg reg;
  std::uint64_t data;
};

std::vector<Write> writes_of(const protocol::CommandStream& s) {
  std::vector<Write> out;
  for (const auto& c : s.commands)
    if (const auto* f = std::get_if<protocol::FramesCmd>(&c.command))
      for (std::size_t i = 0; i < f->size(); ++i) {
        const auto fr = f->view()[i];
        EXPECT_FALSE(fr.read);
        out.push_back({static_cast<Reg>(fr.index), fr.data});
      }
  return out;
}

std::int64_t field(Reg r, const char* name, std::uint64_t data) { return protocol::describe(r).field(name)->get_signed(data); }

std::vector<Write> only(const std::vector<Write>& w, Reg r) {
  std::vector<Write> out;
  for (const auto& x : w)
    if (x.reg == r) out.push_back(x);
  return out;
}

BuiltScene build(const std::string& json, BuildOptions opt = {}) {
  auto s = parse_scene(json, "t.json", ".");
  EXPECT_TRUE(s) << s.error().message;
  auto b = build_commands(*s, opt);
  EXPECT_TRUE(b) << b.error().message;
  return std::move(*b);
}

TEST(SceneBuild, SetupTriangleAndSwap) {
  const auto b = build(R"({"framebuffer": {"width": 64, "height": 32, "format": "RGB565"},
      "clear": {"color": [0.2, 0.4, 0.6]},
      "draws": [{"vertices": [[1, 2, 0, 1, 1, 0, 0], [10.5, 2, 0, 1, 0, 1, 0], [1, 20.03125, 0, 1, 0, 0, 1]]}]})");
  const auto w = writes_of(b.stream);
  ASSERT_FALSE(w.empty());
  const auto fb = only(w, Reg::FB_FORMAT);
  ASSERT_EQ(fb.size(), 1u);
  EXPECT_EQ(field(Reg::FB_FORMAT, "WIDTH", fb[0].data), 64);
  EXPECT_EQ(field(Reg::FB_FORMAT, "HEIGHT", fb[0].data), 32);
  EXPECT_EQ(field(Reg::FB_FORMAT, "FORMAT", fb[0].data), 1);
  ASSERT_EQ(only(w, Reg::CLEAR_COLOR).size(), 1u);
  EXPECT_EQ(only(w, Reg::CLEAR_COLOR)[0].data, 0x336699FFu);  // round(0.2·255)=51, 102, 153, 255
  EXPECT_EQ(only(w, Reg::CLEAR).size(), 1u);
  EXPECT_TRUE(only(w, Reg::CLEAR_Z).empty());  // no depth buffer requested
  const auto verts = only(w, Reg::VERTEX);
  ASSERT_EQ(verts.size(), 3u);
  EXPECT_EQ(field(Reg::VERTEX, "X", verts[0].data), 16);
  EXPECT_EQ(field(Reg::VERTEX, "Y", verts[0].data), 32);
  EXPECT_EQ(field(Reg::VERTEX, "X", verts[1].data), 168);
  EXPECT_EQ(field(Reg::VERTEX, "Y", verts[2].data), 321);  // 20.03125 is a tie: rounds up
  const auto colors = only(w, Reg::COLOR);
  ASSERT_EQ(colors.size(), 3u);
  EXPECT_EQ(field(Reg::COLOR, "R", colors[0].data), 255);
  EXPECT_EQ(field(Reg::COLOR, "G", colors[1].data), 255);
  EXPECT_EQ(field(Reg::COLOR, "Q", colors[2].data), 0xFFFFFFFFll);  // equal w: every Q full scale
  EXPECT_TRUE(only(w, Reg::TEXCOORD).empty());
  // PRIM=LIST precedes the vertices and the swap comes last, to the colour buffer.
  ASSERT_EQ(only(w, Reg::PRIM).size(), 1u);
  EXPECT_EQ(only(w, Reg::PRIM)[0].data, 0u);
  EXPECT_EQ(w.back().reg, Reg::FB_DISPLAY);
  EXPECT_EQ(w.back().data, b.layout.color);
  for (const auto& x : w) EXPECT_EQ(protocol::check_write(protocol::index_of(x.reg), x.data).errors, 0);
}

TEST(SceneBuild, MemoryLayoutIsSequentialAndAligned) {
  std::string rgba;
  for (int i = 0; i < 16 * 8 * 4; ++i) rgba += i ? ",9" : "9";
  const auto b = build(R"({"framebuffer": {"width": 30, "height": 10, "format": "RGB565"}, "clear": {"depth": 0.5},
      "textures": [{"name": "a", "width": 16, "height": 8, "format": "RGBA2222", "rgba": [)" + rgba + R"(]},
                   {"name": "b", "width": 16, "height": 8, "rgba": [)" + rgba + R"(]}]})");
  // colour 30·10·2 = 600 B at 0; depth 30·10·4 = 1200 B at align256(600) = 768;
  // texture a 16·8·1 = 128 B at align256(768 + 1200) = 2048; texture b at 2048 + 256.
  EXPECT_EQ(b.layout.color, 0u);
  ASSERT_TRUE(b.layout.depth);
  EXPECT_EQ(*b.layout.depth, 768u);
  ASSERT_EQ(b.layout.textures.size(), 2u);
  EXPECT_EQ(b.layout.textures[0], 2048u);
  EXPECT_EQ(b.layout.textures[1], 2304u);
  EXPECT_EQ(b.layout.end, 2304u + 512u);
  const auto w = writes_of(b.stream);
  ASSERT_EQ(only(w, Reg::FB_Z).size(), 1u);
  EXPECT_EQ(only(w, Reg::FB_Z)[0].data, 768u);
  ASSERT_EQ(only(w, Reg::CLEAR_DEPTH).size(), 1u);
  EXPECT_EQ(only(w, Reg::CLEAR_DEPTH)[0].data, 8388608u);
  EXPECT_EQ(only(w, Reg::CLEAR_Z).size(), 1u);
  // Uploads: texture a as RGBA2222 (9 → 0 in 2 bits), b as RGBA8888 (9s).
  std::vector<const protocol::UploadCmd*> ups;
  for (const auto& c : b.stream.commands)
    if (const auto* u = std::get_if<protocol::UploadCmd>(&c.command)) ups.push_back(u);
  ASSERT_EQ(ups.size(), 2u);
  EXPECT_EQ(ups[0]->address, 2048u);
  EXPECT_EQ(ups[0]->data, std::vector<std::uint8_t>(128, 0));
  EXPECT_EQ(ups[1]->address, 2304u);
  EXPECT_EQ(ups[1]->data, std::vector<std::uint8_t>(512, 9));
}

// Scene names are file paths, which on Linux need not be UTF-8; the stream's metadata JSON used to
// throw from dump() for such a name instead of building.
TEST(SceneBuild, NonUtf8SceneNameStillBuilds) {
  auto s = parse_scene(R"({"framebuffer": {"width": 8, "height": 8}})", "bad\xff.json", ".");
  ASSERT_TRUE(s) << s.error().message;
  auto b = build_commands(*s);
  ASSERT_TRUE(b) << b.error().message;
  const auto meta = nlohmann::json::parse(b->stream.metadata_json, nullptr, false);
  ASSERT_FALSE(meta.is_discarded()) << b->stream.metadata_json;
  EXPECT_EQ(meta["width"], 8);
  EXPECT_EQ(meta["scene"].get<std::string>().rfind("bad", 0), 0u);
}

TEST(SceneBuild, TooLittleVideoMemoryIsAnError) {
  auto s = parse_scene(R"({"framebuffer": {"width": 1024, "height": 1024}, "clear": {"depth": 1}})", "big.json", ".");
  ASSERT_TRUE(s);
  BuildOptions o;
  o.vram_bytes = 4u << 20;
  auto b = build_commands(*s, o);
  ASSERT_FALSE(b);
  EXPECT_NE(b.error().message.find("big.json: the framebuffer, depth buffer and textures need 8388608 bytes"),
            std::string::npos)
      << b.error().message;
}

TEST(SceneBuild, TexturedDrawStateAndTexcoords) {
  std::string rgba;
  for (int i = 0; i < 8 * 8 * 4; ++i) rgba += i ? ",255" : "255";
  const auto b = build(R"({"framebuffer": {"width": 32, "height": 32},
      "textures": [{"name": "t", "width": 8, "height": 8, "rgba": [)" + rgba + R"(], "wrap": "MIRROR", "filter": "bilinear"}],
      "draws": [{"texture": "t", "z_test": true, "z_write": true, "vertices": [
                  {"x": 0, "y": 0, "w": 1, "u": 2.5, "v": 0}, {"x": 16, "y": 0, "w": 2, "u": 3.5, "v": 0},
                  {"x": 0, "y": 16, "w": 1, "u": 2.5, "v": 1}]},
                {"texture": "t", "z_test": true, "z_write": true, "vertices": []}]})");
  const auto w = writes_of(b.stream);
  ASSERT_EQ(only(w, Reg::TRI_MODE).size(), 1u);  // the second draw's identical state is not re-sent
  const auto mode = only(w, Reg::TRI_MODE)[0].data;
  EXPECT_EQ(field(Reg::TRI_MODE, "TEXTURED", mode), 1);
  EXPECT_EQ(field(Reg::TRI_MODE, "Z_TEST", mode), 1);
  EXPECT_EQ(field(Reg::TRI_MODE, "Z_WRITE", mode), 1);
  ASSERT_EQ(only(w, Reg::TEX_FMT).size(), 1u);
  const auto fmt = only(w, Reg::TEX_FMT)[0].data;
  EXPECT_EQ(field(Reg::TEX_FMT, "WRAP_S", fmt), 2);
  EXPECT_EQ(field(Reg::TEX_FMT, "BILINEAR", fmt), 1);
  EXPECT_EQ(field(Reg::TEX_FMT, "WIDTH_LOG2", fmt), 3);
  EXPECT_EQ(only(w, Reg::TEX_BASE)[0].data, b.layout.textures[0]);
  const auto tc = only(w, Reg::TEXCOORD);
  const auto col = only(w, Reg::COLOR);
  ASSERT_EQ(tc.size(), 3u);
  // MIRROR offset = 2·floor(2.5 / 2) = 2: u − u_off = 0.5, 1.5, 0.5. Vertex 1 has w = 2: Q ≈ 2^31.
  const double q1 = static_cast<double>(field(Reg::COLOR, "Q", col[1].data));
  EXPECT_NEAR(q1, 4294967295.0 / 2, 0.5);
  EXPECT_NEAR(field(Reg::TEXCOORD, "S", tc[0].data), 0.5 * (1 << 24), 1);
  EXPECT_NEAR(field(Reg::TEXCOORD, "S", tc[1].data) * 256.0 / q1, 1.5, 1e-7);
  EXPECT_NEAR(field(Reg::TEXCOORD, "T", tc[2].data), 1.0 * (1 << 24), 1);
}

TEST(SceneBuild, PipelineErrorsPointAtTheTriangle) {
  std::string rgba;
  for (int i = 0; i < 8 * 8 * 4; ++i) rgba += i ? ",1" : "1";
  auto s = parse_scene(R"({"framebuffer": {"width": 32, "height": 32},
      "textures": [{"name": "t", "width": 8, "height": 8, "rgba": [)" + rgba + R"(], "wrap": "CLAMP"}],
      "draws": [{"vertices": [[0,0],[1,0],[0,1]]},
                {"texture": "t", "vertices": [[0,0],[1,0],[0,1], [0,0,0,1,1,1,1,1,500,0],[9,0,0,1,1,1,1,1,500,0],[0,9,0,1,1,1,1,1,500,0]]}]})",
                       "bad.json", ".");
  ASSERT_TRUE(s) << s.error().message;
  auto b = build_commands(*s);
  ASSERT_FALSE(b);
  EXPECT_NE(b.error().message.find("bad.json: draws[1].vertices[3..5] (triangle 1): "), std::string::npos)
      << b.error().message;
}

TEST(SceneBuild, OffscreenHugeTrianglesAreClippedNotRejected) {
  const auto b = build(R"({"framebuffer": {"width": 16, "height": 16},
      "draws": [{"vertices": [[-100000, -100000], [100000, -50], [8, 90000]]}]})");
  const auto verts = only(writes_of(b.stream), Reg::VERTEX);
  EXPECT_GE(verts.size(), 3u);
  EXPECT_EQ(verts.size() % 3, 0u);
  EXPECT_EQ(b.stats.clipped, 1u);
}

}  // namespace
}  // namespace gpubridge::scene
