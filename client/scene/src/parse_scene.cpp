// JSON → Scene. Every value is validated here, so build_commands only meets values the
// geometry pipeline accepts (except triangle-level limits, which it reports with the triangle).
#include <bit>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "base64.hpp"
#include "gpubridge/scene/scene.hpp"
#include "json_reader.hpp"

namespace gpubridge::scene {
namespace {

using nlohmann::json;
using R = JsonReader;

constexpr std::string_view kFormats[] = {"RGBA8888", "RGB565", "RGBA2222"};
constexpr std::string_view kWraps[] = {"REPEAT", "CLAMP", "MIRROR"};
constexpr std::string_view kFilters[] = {"nearest", "bilinear"};
constexpr std::string_view kDepthFuncs[] = {"NEVER", "LESS", "EQUAL", "LEQUAL", "GREATER", "NOTEQUAL", "GEQUAL", "ALWAYS"};
constexpr std::string_view kBlends[] = {"OFF", "ALPHA", "ADD", "MULTIPLY"};
constexpr std::string_view kTextureModes[] = {"modulate", "decal"};
constexpr std::string_view kCulls[] = {"none", "back", "front"};

class Parser {
 public:
  Parser(std::string_view name, std::filesystem::path base, const Limits& limits)
      : r_(std::string(name)), base_(std::move(base)), limits_(limits) {}

  Result<Scene> parse(std::string_view text) {
    json doc = json::parse(text, nullptr, false);
    if (doc.is_discarded()) {
      // Re-parse with exceptions only to get the position of the syntax error.
      try {
        const json unused = json::parse(text);
        (void)unused;
      } catch (const json::exception& e) {
        // "[json.exception.parse_error.101] parse error at line 2, column 3: ..." → keep the text.
        std::string_view what = e.what();
        if (const auto close = what.find("] "); close != std::string_view::npos) what.remove_prefix(close + 2);
        return r_.error("", fmt::format("not valid JSON: {}", what));
      }
      return r_.error("", "not valid JSON");
    }
    if (auto o = r_.object(doc, "(top level)"); !o) return o.error();
    if (auto k = r_.only_keys(doc, "", {"format", "version", "comment", "framebuffer", "clear", "textures", "draws"}); !k)
      return k.error();
    Scene s;
    s.name = r_.file();
    if (doc.contains("format")) {
      auto f = r_.string(doc["format"], "format");
      if (!f) return f.error();
      if (*f != "gpubridge-scene") return r_.error("format", fmt::format("\"{}\" is not \"gpubridge-scene\"", *f));
    }
    if (doc.contains("version"))
      if (auto v = r_.uint_in(doc["version"], "version", 1, 1); !v) return v.error();
    if (!doc.contains("framebuffer")) return r_.error("framebuffer", "missing (give at least width and height)");
    if (auto f = framebuffer(doc["framebuffer"], s); !f) return f.error();
    if (doc.contains("clear"))
      if (auto c = clear(doc["clear"], s); !c) return c.error();
    if (doc.contains("textures"))
      if (auto t = textures(doc["textures"], s); !t) return t.error();
    if (doc.contains("draws"))
      if (auto d = draws(doc["draws"], s); !d) return d.error();
    return s;
  }

 private:
  Result<void> framebuffer(const json& j, Scene& s) {
    const std::string p = "framebuffer";
    if (auto o = r_.object(j, p); !o) return o.error();
    if (auto k = r_.only_keys(j, p, {"width", "height", "format", "depth"}); !k) return k;
    if (!j.contains("width") || !j.contains("height")) return r_.error(p, "needs \"width\" and \"height\"");
    auto w = r_.uint_in(j["width"], R::child(p, "width"), 1, protocol::kMaxFramebufferDim);
    if (!w) return w.error();
    auto h = r_.uint_in(j["height"], R::child(p, "height"), 1, protocol::kMaxFramebufferDim);
    if (!h) return h.error();
    s.width = *w;
    s.height = *h;
    if (j.contains("format")) {
      auto f = r_.choice(j["format"], R::child(p, "format"), kFormats);
      if (!f) return f.error();
      s.format = static_cast<protocol::PixelFormat>(*f);
    }
    if (j.contains("depth")) {
      auto d = r_.boolean(j["depth"], R::child(p, "depth"));
      if (!d) return d.error();
      s.depth_buffer = *d;
    }
    return {};
  }

  Result<geometry::Vec4> color4(const json& j, std::string_view p) {
    if (auto a = r_.array(j, p); !a) return a.error();
    if (j.size() != 3 && j.size() != 4) return r_.error(p, fmt::format("expected [r, g, b] or [r, g, b, a], got {} values", j.size()));
    double c[4] = {0, 0, 0, 1};
    for (std::size_t i = 0; i < j.size(); ++i) {
      auto v = r_.number_in(j[i], R::index(p, i), 0, 1);
      if (!v) return v.error();
      c[i] = *v;
    }
    return geometry::Vec4{c[0], c[1], c[2], c[3]};
  }

  Result<void> clear(const json& j, Scene& s) {
    const std::string p = "clear";
    if (auto o = r_.object(j, p); !o) return o.error();
    if (auto k = r_.only_keys(j, p, {"color", "depth"}); !k) return k;
    if (j.contains("color")) {
      auto c = color4(j["color"], R::child(p, "color"));
      if (!c) return c.error();
      s.clear_color = *c;
    }
    if (j.contains("depth")) {
      auto d = r_.number_in(j["depth"], R::child(p, "depth"), 0, 1);
      if (!d) return d.error();
      s.clear_depth = *d;
      s.depth_buffer = true;
    }
    return {};
  }

  // Textures are at most 1024 texels per side: a larger PNG is refused from its header.
  static PngLimits texture_png_limits() { return PngLimits{1u << protocol::kMaxTextureLog2, 0, "a texture"}; }

  Result<Image> texture_image(const json& j, const std::string& p) {
    const int sources = j.contains("png") + j.contains("png_base64") + j.contains("rgba");
    if (sources != 1) return r_.error(p, "give exactly one of \"png\" (file), \"png_base64\" or \"rgba\" (inline bytes)");
    if (j.contains("png")) {
      auto f = r_.string(j["png"], R::child(p, "png"));
      if (!f) return f.error();
      const std::filesystem::path path = std::filesystem::path(*f).is_absolute() ? std::filesystem::path(*f) : base_ / *f;
      auto img = load_png(path, texture_png_limits());
      if (!img) return r_.error(R::child(p, "png"), img.error().message);
      return img;
    }
    if (j.contains("png_base64")) {
      auto t = r_.string(j["png_base64"], R::child(p, "png_base64"));
      if (!t) return t.error();
      auto bytes = decode_base64(*t);
      if (!bytes) return r_.error(R::child(p, "png_base64"), "not valid base64");
      auto img = decode_png(*bytes, "inline PNG", texture_png_limits());
      if (!img) return r_.error(R::child(p, "png_base64"), img.error().message);
      return img;
    }
    // Inline bytes: width × height × 4 numbers 0..255, rows top to bottom, RGBA.
    if (!j.contains("width") || !j.contains("height")) return r_.error(p, "inline \"rgba\" needs \"width\" and \"height\"");
    auto w = r_.uint_in(j["width"], R::child(p, "width"), 1, 1u << protocol::kMaxTextureLog2);
    if (!w) return w.error();
    auto h = r_.uint_in(j["height"], R::child(p, "height"), 1, 1u << protocol::kMaxTextureLog2);
    if (!h) return h.error();
    const std::string bp = R::child(p, "rgba");
    if (auto a = r_.array(j["rgba"], bp); !a) return a.error();
    const std::size_t n = std::size_t{*w} * *h * 4;
    if (j["rgba"].size() != n)
      return r_.error(bp, fmt::format("expected {} numbers ({} x {} x RGBA), got {}", n, *w, *h, j["rgba"].size()));
    Image img;
    img.width = *w;
    img.height = *h;
    img.rgba.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      auto v = r_.uint_in(j["rgba"][i], R::index(bp, i), 0, 255);
      if (!v) return v.error();
      img.rgba[i] = static_cast<std::uint8_t>(*v);
    }
    return img;
  }

  Result<void> textures(const json& j, Scene& s) {
    if (auto a = r_.array(j, "textures"); !a) return a.error();
    if (j.size() > limits_.max_textures)
      return r_.error("textures", fmt::format("{} textures exceed the limit of {}", j.size(), limits_.max_textures));
    for (std::size_t i = 0; i < j.size(); ++i) {
      const std::string p = R::index("textures", i);
      const json& t = j[i];
      if (auto o = r_.object(t, p); !o) return o.error();
      if (auto k = r_.only_keys(t, p, {"name", "png", "png_base64", "rgba", "width", "height", "format", "wrap", "wrap_s",
                                       "wrap_t", "filter"});
          !k)
        return k;
      Texture tex;
      if (!t.contains("name")) return r_.error(p, "missing \"name\" (draws refer to textures by name)");
      auto name = r_.string(t["name"], R::child(p, "name"));
      if (!name) return name.error();
      for (const auto& other : s.textures)
        if (other.name == *name) return r_.error(R::child(p, "name"), fmt::format("duplicate texture name \"{}\"", *name));
      tex.name = *name;
      auto img = texture_image(t, p);
      if (!img) return img.error();
      for (unsigned d : {img->width, img->height})
        if (!std::has_single_bit(d) || d < 8 || d > 1024)
          return r_.error(p, fmt::format("texture is {}x{}; width and height must be powers of two from 8 to 1024",
                                         img->width, img->height));
      tex.image = std::move(*img);
      if (t.contains("format")) {
        auto f = r_.choice(t["format"], R::child(p, "format"), kFormats);
        if (!f) return f.error();
        tex.format = static_cast<protocol::PixelFormat>(*f);
      }
      if (auto w = wraps(t, p, tex.wrap_s, tex.wrap_t); !w) return w;
      if (t.contains("filter")) {
        auto f = r_.choice(t["filter"], R::child(p, "filter"), kFilters);
        if (!f) return f.error();
        tex.bilinear = *f == 1;
      }
      s.textures.push_back(std::move(tex));
    }
    return {};
  }

  // "wrap" sets both axes; "wrap_s" / "wrap_t" set one.
  Result<void> wraps(const json& j, const std::string& p, protocol::Wrap& ws, protocol::Wrap& wt) {
    for (const char* key : {"wrap", "wrap_s", "wrap_t"}) {
      if (!j.contains(key)) continue;
      auto w = r_.choice(j[key], R::child(p, key), kWraps);
      if (!w) return w.error();
      const auto v = static_cast<protocol::Wrap>(*w);
      if (std::string_view(key) != "wrap_t") ws = v;
      if (std::string_view(key) != "wrap_s") wt = v;
    }
    return {};
  }

  Result<void> draws(const json& j, Scene& s) {
    if (auto a = r_.array(j, "draws"); !a) return a.error();
    if (j.size() > limits_.max_draws)
      return r_.error("draws", fmt::format("{} draws exceed the limit of {}", j.size(), limits_.max_draws));
    for (std::size_t i = 0; i < j.size(); ++i) {
      auto d = draw(j[i], R::index("draws", i), s);
      if (!d) return d.error();
      s.draws.push_back(std::move(*d));
    }
    return {};
  }

  Result<bool> flag(const json& j, const std::string& p, const char* key, bool def) {
    if (!j.contains(key)) return def;
    return r_.boolean(j[key], R::child(p, key));
  }

  Result<Draw> draw(const json& j, const std::string& p, Scene& s) {
    if (auto o = r_.object(j, p); !o) return o.error();
    if (auto k = r_.only_keys(j, p, {"comment", "gouraud", "z_test", "z_func", "z_write", "blend", "dither", "temporal",
                                     "dither_phase", "write_mask", "texture", "texture_mode", "wrap", "wrap_s", "wrap_t", "filter", "cull", "scissor",
                                     "color", "vertices"});
        !k)
      return k.error();
    Draw d;
    auto& st = d.state;
    auto g = flag(j, p, "gouraud", true);
    if (!g) return g.error();
    st.gouraud = *g;
    auto zt = flag(j, p, "z_test", false);
    if (!zt) return zt.error();
    st.z_test = *zt;
    auto zw = flag(j, p, "z_write", false);
    if (!zw) return zw.error();
    st.z_write = *zw;
    auto di = flag(j, p, "dither", false);
    if (!di) return di.error();
    st.dither = *di;
    auto te = flag(j, p, "temporal", false);
    if (!te) return te.error();
    st.temporal = *te;
    if (j.contains("dither_phase")) {
      auto ph = r_.uint_in(j["dither_phase"], R::child(p, "dither_phase"), 0, 15);
      if (!ph) return ph.error();
      st.dither_phase = *ph;
    }
    if (j.contains("z_func")) {
      auto f = r_.choice(j["z_func"], R::child(p, "z_func"), kDepthFuncs);
      if (!f) return f.error();
      st.z_func = static_cast<protocol::DepthFunc>(*f);
    }
    if (j.contains("blend")) {
      auto b = r_.choice(j["blend"], R::child(p, "blend"), kBlends);
      if (!b) return b.error();
      st.blend = static_cast<protocol::BlendMode>(*b);
    }
    if (j.contains("write_mask")) {
      auto m = r_.string(j["write_mask"], R::child(p, "write_mask"));
      if (!m) return m.error();
      if (m->find_first_not_of("rgbaRGBA") != std::string::npos)
        return r_.error(R::child(p, "write_mask"), "use the letters r, g, b, a for the channels to write (\"rgb\", \"\")");
      auto has = [&](char c) { return m->find(c) != std::string::npos || m->find(static_cast<char>(c - 32)) != std::string::npos; };
      st.mask_r = !has('r');
      st.mask_g = !has('g');
      st.mask_b = !has('b');
      st.mask_a = !has('a');
    }
    if (st.z_test || st.z_write) s.depth_buffer = true;
    if (j.contains("texture")) {
      auto name = r_.string(j["texture"], R::child(p, "texture"));
      if (!name) return name.error();
      for (std::size_t t = 0; t < s.textures.size(); ++t)
        if (s.textures[t].name == *name) d.texture = t;
      if (!d.texture) return r_.error(R::child(p, "texture"), fmt::format("no texture named \"{}\" in \"textures\"", *name));
      st.textured = true;
    }
    if (j.contains("texture_mode")) {
      auto m = r_.choice(j["texture_mode"], R::child(p, "texture_mode"), kTextureModes);
      if (!m) return m.error();
      st.tex_decal = *m == 1;
    }
    protocol::Wrap ws{}, wt{};
    const bool any_wrap = j.contains("wrap") || j.contains("wrap_s") || j.contains("wrap_t");
    if (d.texture) {
      ws = s.textures[*d.texture].wrap_s;
      wt = s.textures[*d.texture].wrap_t;
    }
    if (auto w = wraps(j, p, ws, wt); !w) return w.error();
    if (any_wrap) {
      d.wrap_s = ws;
      d.wrap_t = wt;
    }
    if (j.contains("filter")) {
      auto f = r_.choice(j["filter"], R::child(p, "filter"), kFilters);
      if (!f) return f.error();
      d.bilinear = *f == 1;
    }
    if (j.contains("cull")) {
      auto c = r_.choice(j["cull"], R::child(p, "cull"), kCulls);
      if (!c) return c.error();
      d.cull = static_cast<geometry::CullMode>(*c);
    }
    if (j.contains("scissor")) {
      const std::string sp = R::child(p, "scissor");
      if (auto a = r_.array(j["scissor"], sp); !a) return a.error();
      if (j["scissor"].size() != 4) return r_.error(sp, "expected [x0, y0, x1, y1]");
      std::array<unsigned, 4> sc{};
      for (std::size_t i = 0; i < 4; ++i) {
        auto v = r_.uint_in(j["scissor"][i], R::index(sp, i), 0, protocol::kMaxFramebufferDim);
        if (!v) return v.error();
        sc[i] = *v;
      }
      d.scissor = sc;
    }
    geometry::Vec4 base_color{1, 1, 1, 1};
    if (j.contains("color")) {
      auto c = color4(j["color"], R::child(p, "color"));
      if (!c) return c.error();
      base_color = *c;
    }
    if (!j.contains("vertices")) return r_.error(p, "missing \"vertices\" (a triangle list)");
    const std::string vp = R::child(p, "vertices");
    const json& vs = j["vertices"];
    if (auto a = r_.array(vs, vp); !a) return a.error();
    if (vs.size() % 3 != 0)
      return r_.error(vp, fmt::format("{} vertices is not a multiple of 3 (a triangle list)", vs.size()));
    vertex_total_ += vs.size();
    if (vertex_total_ > limits_.max_vertices)
      return r_.error(vp, fmt::format("the scene has more than {} vertices", limits_.max_vertices));
    d.vertices.reserve(vs.size());
    for (std::size_t i = 0; i < vs.size(); ++i) {
      auto v = vertex(vs[i], R::index(vp, i), base_color);
      if (!v) return v.error();
      d.vertices.push_back(*v);
    }
    return d;
  }

  // {"x":…, "y":…, "z":…, "w":…, "r":…, "g":…, "b":…, "a":…, "u":…, "v":…} or the same values as
  // an array in that order (at least x and y).
  Result<geometry::ScreenVertex> vertex(const json& j, const std::string& p, geometry::Vec4 base_color) {
    static constexpr const char* keys[] = {"x", "y", "z", "w", "r", "g", "b", "a", "u", "v"};
    double val[10] = {0, 0, 0, 1, base_color.x, base_color.y, base_color.z, base_color.w, 0, 0};
    if (j.is_array()) {
      if (j.size() < 2 || j.size() > 10)
        return r_.error(p, fmt::format("a vertex array needs 2 to 10 numbers [x, y, z, w, r, g, b, a, u, v], got {}", j.size()));
      for (std::size_t i = 0; i < j.size(); ++i) {
        auto v = r_.number(j[i], fmt::format("{}[{}] ({})", p, i, keys[i]));
        if (!v) return v.error();
        val[i] = *v;
      }
    } else if (j.is_object()) {
      if (auto k = r_.only_keys(j, p, {"x", "y", "z", "w", "r", "g", "b", "a", "u", "v"}); !k) return k.error();
      if (!j.contains("x") || !j.contains("y")) return r_.error(p, "a vertex needs \"x\" and \"y\"");
      for (int i = 0; i < 10; ++i) {
        if (!j.contains(keys[i])) continue;
        auto v = r_.number(j[keys[i]], R::child(p, keys[i]));
        if (!v) return v.error();
        val[i] = *v;
      }
    } else {
      return r_.error(p, fmt::format("expected a vertex object or array, got {}", json_type_name(j)));
    }
    auto where = [&](int i) { return j.is_array() ? fmt::format("{}[{}] ({})", p, i, keys[i]) : R::child(p, keys[i]); };
    for (int i : {0, 1})
      if (std::fabs(val[i]) > limits_.max_abs_xy)
        return r_.error(where(i), fmt::format("{} px is beyond ±{} px", val[i], limits_.max_abs_xy));
    if (val[2] < 0 || val[2] > 1) return r_.error(where(2), fmt::format("{} is outside [0, 1]", val[2]));
    if (val[3] < limits_.min_w || val[3] > limits_.max_w)
      return r_.error(where(3), fmt::format("{} is outside [{}, {}] (w is the perspective divisor, > 0)", val[3],
                                            limits_.min_w, limits_.max_w));
    for (int i = 4; i < 8; ++i)
      if (val[i] < 0 || val[i] > 1) return r_.error(where(i), fmt::format("{} is outside [0, 1]", val[i]));
    for (int i : {8, 9})
      if (std::fabs(val[i]) > 1e6) return r_.error(where(i), fmt::format("{} is beyond ±1e6 texture sizes", val[i]));
    geometry::ScreenVertex v;
    v.x = val[0];
    v.y = val[1];
    v.z = val[2];
    v.w = val[3];
    v.color = {val[4], val[5], val[6], val[7]};
    v.uv = {val[8], val[9]};
    return v;
  }

  JsonReader r_;
  std::filesystem::path base_;
  const Limits& limits_;
  std::size_t vertex_total_ = 0;
};

}  // namespace

Result<Scene> parse_scene(std::string_view json_text, std::string_view name_for_errors,
                          const std::filesystem::path& base_dir, const Limits& limits) {
  if (json_text.size() > limits.max_file_bytes)
    return make_error(fmt::format("{}: {} bytes exceed the scene size limit of {} bytes", name_for_errors, json_text.size(),
                                  limits.max_file_bytes));
  return Parser(name_for_errors, base_dir, limits).parse(json_text);
}

Result<Scene> read_scene_file(const std::filesystem::path& path, const Limits& limits) {
  const std::string name = path.string();
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return make_error(fmt::format("{}: cannot read the scene file: {}", name, ec.message()));
  if (size > limits.max_file_bytes)
    return make_error(fmt::format("{}: {} bytes exceed the scene size limit of {} bytes", name, size, limits.max_file_bytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(fmt::format("{}: cannot open the scene file", name));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), name, path.parent_path(), limits);
}

}  // namespace gpubridge::scene
