// Scene JSON parsing: values land where they should, and every kind of bad input gives an error
// naming the file, the JSON path and the problem.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "gpubridge/scene/scene.hpp"

namespace gpubridge::scene {
namespace {

Result<Scene> parse(const std::string& text, const std::filesystem::path& base = ".") {
  return parse_scene(text, "scene.json", base);
}

std::string error_of(const std::string& text) {
  auto r = parse(text);
  EXPECT_FALSE(r) << text;
  return r ? std::string() : r.error().message;
}

const char* kMinimal = R"({
  "framebuffer": {"width": 64, "height": 32, "format": "RGB565"},
  "clear": {"color": [0.2, 0.4, 0.6]},
  "draws": [{"vertices": [{"x": 1, "y": 2, "r": 0.5}, [10, 2, 0.25, 2, 1, 0, 0, 1, 0.5, 0.75], [1, 20]]}]
})";

TEST(SceneParse, MinimalSceneValues) {
  auto s = parse(kMinimal);
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->width, 64u);
  EXPECT_EQ(s->height, 32u);
  EXPECT_EQ(s->format, protocol::PixelFormat::RGB565);
  EXPECT_FALSE(s->depth_buffer);
  EXPECT_DOUBLE_EQ(s->clear_color.y, 0.4);
  EXPECT_DOUBLE_EQ(s->clear_color.w, 1.0);  // alpha defaults to 1
  ASSERT_EQ(s->draws.size(), 1u);
  const auto& v = s->draws[0].vertices;
  ASSERT_EQ(v.size(), 3u);
  EXPECT_DOUBLE_EQ(v[0].x, 1);
  EXPECT_DOUBLE_EQ(v[0].color.x, 0.5);
  EXPECT_DOUBLE_EQ(v[0].color.y, 1.0);  // defaults: white, z 0, w 1
  EXPECT_DOUBLE_EQ(v[0].w, 1.0);
  EXPECT_DOUBLE_EQ(v[1].z, 0.25);
  EXPECT_DOUBLE_EQ(v[1].w, 2);
  EXPECT_DOUBLE_EQ(v[1].color.y, 0);
  EXPECT_DOUBLE_EQ(v[1].uv.x, 0.5);
  EXPECT_DOUBLE_EQ(v[1].uv.y, 0.75);
  EXPECT_DOUBLE_EQ(v[2].y, 20);
  EXPECT_TRUE(s->draws[0].state.gouraud);
}

TEST(SceneParse, DrawStateAndDepthBuffer) {
  auto s = parse(R"({"framebuffer": {"width": 8, "height": 8},
    "draws": [{"gouraud": false, "z_test": true, "z_func": "lequal", "z_write": true, "blend": "ALPHA",
               "dither": true, "temporal": true, "dither_phase": 13, "write_mask": "rg", "cull": "back", "scissor": [1, 2, 3, 4], "color": [0, 0, 1],
               "vertices": [[0,0],[1,0],[0,1]]}]})");
  ASSERT_TRUE(s) << s.error().message;
  const auto& d = s->draws[0];
  EXPECT_FALSE(d.state.gouraud);
  EXPECT_TRUE(d.state.z_test);
  EXPECT_EQ(d.state.z_func, protocol::DepthFunc::LessEqual);
  EXPECT_EQ(d.state.blend, protocol::BlendMode::Alpha);
  EXPECT_TRUE(d.state.dither);
  EXPECT_TRUE(d.state.temporal);
  EXPECT_EQ(d.state.dither_phase, 13u);
  EXPECT_FALSE(d.state.mask_r);
  EXPECT_FALSE(d.state.mask_g);
  EXPECT_TRUE(d.state.mask_b);
  EXPECT_TRUE(d.state.mask_a);
  EXPECT_EQ(d.cull, geometry::CullMode::Back);
  EXPECT_EQ(*d.scissor, (std::array<unsigned, 4>{1, 2, 3, 4}));
  EXPECT_DOUBLE_EQ(d.vertices[0].color.z, 1);
  EXPECT_DOUBLE_EQ(d.vertices[0].color.x, 0);
  EXPECT_TRUE(s->depth_buffer);  // implied by the depth test
}

TEST(SceneParse, InlineAndFileTextures) {
  const auto dir = std::filesystem::temp_directory_path() / "gpubridge_scene_parse_test";
  std::filesystem::create_directories(dir / "tex");
  Image img;
  img.width = 8;
  img.height = 16;
  img.rgba.assign(8 * 16 * 4, 0);
  img.pixel(3, 5)[0] = 200;
  ASSERT_TRUE(save_png(dir / "tex" / "a.png", img));
  std::string rgba;
  for (int i = 0; i < 8 * 8 * 4; ++i) rgba += (i ? "," : "") + std::to_string(i % 256);
  auto s = parse(R"({"framebuffer": {"width": 8, "height": 8},
      "textures": [{"name": "file", "png": "tex/a.png", "format": "RGBA2222", "wrap": "CLAMP", "wrap_t": "MIRROR", "filter": "bilinear"},
                   {"name": "inline", "width": 8, "height": 8, "rgba": [)" + rgba + R"(]}],
      "draws": [{"texture": "inline", "texture_mode": "decal", "wrap_s": "MIRROR", "vertices": []}]})",
                 dir);
  ASSERT_TRUE(s) << s.error().message;
  ASSERT_EQ(s->textures.size(), 2u);
  EXPECT_EQ(s->textures[0].image, img);
  EXPECT_EQ(s->textures[0].format, protocol::PixelFormat::RGBA2222);
  EXPECT_EQ(s->textures[0].wrap_s, protocol::Wrap::Clamp);
  EXPECT_EQ(s->textures[0].wrap_t, protocol::Wrap::Mirror);
  EXPECT_TRUE(s->textures[0].bilinear);
  EXPECT_EQ(s->textures[1].image.rgba[13], 13);
  EXPECT_EQ(s->draws[0].texture, std::size_t{1});
  EXPECT_TRUE(s->draws[0].state.textured);
  EXPECT_TRUE(s->draws[0].state.tex_decal);
  EXPECT_EQ(s->draws[0].wrap_s, protocol::Wrap::Mirror);
  EXPECT_EQ(s->draws[0].wrap_t, protocol::Wrap::Repeat);  // from the texture
  std::filesystem::remove_all(dir);
}

std::string base64(const std::vector<std::uint8_t>& b) {
  static const char* a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < b.size(); i += 3) {
    const std::uint32_t n = (b[i] << 16) | ((i + 1 < b.size() ? b[i + 1] : 0) << 8) | (i + 2 < b.size() ? b[i + 2] : 0);
    out += a[(n >> 18) & 63];
    out += a[(n >> 12) & 63];
    out += i + 1 < b.size() ? a[(n >> 6) & 63] : '=';
    out += i + 2 < b.size() ? a[n & 63] : '=';
  }
  return out;
}

TEST(SceneParse, Base64PngTexture) {
  Image img;
  img.width = 8;
  img.height = 8;
  img.rgba.assign(8 * 8 * 4, 77);
  auto png = encode_png(img);
  ASSERT_TRUE(png);
  auto s = parse(R"({"framebuffer": {"width": 8, "height": 8}, "textures": [{"name": "t", "png_base64": ")" +
                 base64(*png) + R"("}]})");
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->textures[0].image, img);
  const auto e = error_of(R"({"framebuffer": {"width": 8, "height": 8}, "textures": [{"name": "t", "png_base64": "@@@"}]})");
  EXPECT_NE(e.find("textures[0].png_base64: not valid base64"), std::string::npos) << e;
}

TEST(SceneParse, ErrorsNameFilePathAndProblem) {
  struct Case {
    std::string json, expect;
  };
  const std::string fb = R"("framebuffer": {"width": 8, "height": 8})";
  const Case cases[] = {
      {R"({"framebuffer": {"width": 8, "height": 8}, "draws": [{"vertices": [[0,0],[1,0],[0,1]]}, {"vertices": [[0,0],{"x": 1e999, "y": 0},[0,1]]}]})",
       "scene.json: not valid JSON: number overflow parsing '1e999'"},
      {"{" + fb + R"(, "draws": [{"vertices": [[0,0],[1,0]]}]})", "draws[0].vertices: 2 vertices is not a multiple of 3"},
      {"{" + fb + R"(, "draws": [{"vertices": [[0,0],[1,"a"],[0,1]]}]})", "draws[0].vertices[1][1] (y): expected a number, got a string"},
      {"{" + fb + R"(, "draws": [{"vertices": [[0,0,1.5],[1,0],[0,1]]}]})", "draws[0].vertices[0][2] (z): 1.5 is outside [0, 1]"},
      {"{" + fb + R"(, "draws": [{"vertices": [{"x":0,"y":0,"w":0},[1,0],[0,1]]}]})", "draws[0].vertices[0].w: 0 is outside"},
      {"{" + fb + R"(, "draws": [{"vertices": [{"x":0,"y":0,"colour":1},[1,0],[0,1]]}]})", "draws[0].vertices[0].colour: unknown key"},
      {"{" + fb + R"(, "draws": [{"texture": "nope", "vertices": []}]})", "draws[0].texture: no texture named \"nope\""},
      {"{" + fb + R"(, "draws": [{"blend": "SCREEN", "vertices": []}]})", "draws[0].blend: \"SCREEN\" is not one of: OFF, ALPHA, ADD, MULTIPLY"},
      {"{" + fb + R"(, "draws": [{"write_mask": "xyz", "vertices": []}]})", "draws[0].write_mask: use the letters"},
      {"{" + fb + R"(, "draws": [{"dither_phase": 16, "vertices": []}]})", "draws[0].dither_phase: 16 is outside 0..15"},
      {"{" + fb + R"(, "textures": [{"name": "t", "width": 12, "height": 8, "rgba": []}]})", "textures[0].rgba: expected 384 numbers"},
      {"{" + fb + R"(, "textures": [{"name": "t", "width": 8, "height": 8, "rgba": [1]}]})", "expected 256 numbers"},
      {"{" + fb + R"(, "textures": [{"name": "t", "png": "missing.png"}]})", "textures[0].png:"},
      {"{" + fb + R"(, "textures": [{"name": "t"}]})", "textures[0]: give exactly one of"},
      {R"({"framebuffer": {"width": 0, "height": 8}})", "framebuffer.width: 0 is outside 1..1024"},
      {R"({"framebuffer": {"width": 8.5, "height": 8}})", "framebuffer.width: expected a whole number"},
      {R"({"draws": []})", "framebuffer: missing"},
      {R"({"framebuffer": {"width": 8, "height": 8}, "clear": {"color": [0, 2, 0]}})", "clear.color[1]: 2 is outside [0, 1]"},
      {R"([1, 2])", "scene.json: (top level): expected an object, got an array"},
      {"{\n  \"framebuffer\": {,\n}", "scene.json: not valid JSON: parse error at line 2, column 19"},
  };
  for (const auto& c : cases) {
    const auto e = error_of(c.json);
    EXPECT_NE(e.find(c.expect), std::string::npos) << "got: " << e << "\nwanted: " << c.expect;
    EXPECT_EQ(e.rfind("scene.json: ", 0), 0u) << e;
  }
}

TEST(SceneParse, NonPowerOfTwoTextureRejected) {
  std::string rgba;
  for (int i = 0; i < 12 * 8 * 4; ++i) rgba += i ? ",0" : "0";
  const auto e = error_of(R"({"framebuffer": {"width": 8, "height": 8}, "textures": [{"name": "t", "width": 12, "height": 8, "rgba": [)" +
                          rgba + "]}]}");
  EXPECT_NE(e.find("powers of two from 8 to 1024"), std::string::npos) << e;
}

TEST(SceneParse, LimitsAreCheckedBeforeWork) {
  Limits l;
  l.max_vertices = 3;
  auto r = parse_scene(R"({"framebuffer": {"width": 8, "height": 8}, "draws": [{"vertices": [[0,0],[1,0],[0,1],[0,0],[1,0],[0,1]]}]})",
                       "s.json", ".", l);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("more than 3 vertices"), std::string::npos);
  l = {};
  l.max_file_bytes = 10;
  r = parse_scene(kMinimal, "s.json", ".", l);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("size limit"), std::string::npos);
  const auto missing = read_scene_file("/nonexistent/dir/scene.json");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("/nonexistent/dir/scene.json"), std::string::npos);
}

TEST(SceneParse, ExampleScenesParse) {
  std::size_t n = 0;
  for (const auto& e : std::filesystem::directory_iterator(GPUBRIDGE_EXAMPLE_SCENES)) {
    if (e.path().extension() != ".json") continue;
    auto s = read_scene_file(e.path());
    EXPECT_TRUE(s) << (s ? "" : s.error().message);
    ++n;
  }
  EXPECT_GE(n, 3u);
}

}  // namespace
}  // namespace gpubridge::scene
