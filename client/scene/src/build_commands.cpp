// Scene → memory layout + command stream, through the host geometry pipeline.
#include <algorithm>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "gpubridge/common/json_text.hpp"
#include "gpubridge/geometry/encode.hpp"
#include "gpubridge/scene/scene.hpp"

namespace gpubridge::scene {
namespace {

using protocol::Reg;

std::uint64_t align_up(std::uint64_t v, std::uint64_t a) { return (v + a - 1) / a * a; }

template <class T>
Result<T> in_scene(const Scene& s, Result<T> r) {
  if (r) return r;
  return make_error(fmt::format("{}: {}", s.name, r.error().message));
}

}  // namespace

Result<MemoryLayout> plan_memory(const Scene& scene, std::uint64_t vram_bytes) {
  MemoryLayout m;
  std::uint64_t next = 0;
  auto take = [&](std::uint64_t bytes) {
    const std::uint64_t at = next;
    next = align_up(at + bytes, kRegionAlignment);
    return at;
  };
  m.color = static_cast<std::uint32_t>(take(std::uint64_t{scene.width} * scene.height * protocol::bytes_per_pixel(scene.format)));
  if (scene.depth_buffer) m.depth = static_cast<std::uint32_t>(take(std::uint64_t{scene.width} * scene.height * 4));
  for (const auto& t : scene.textures)
    m.textures.push_back(static_cast<std::uint32_t>(take(std::uint64_t{t.image.width} * t.image.height *
                                                        protocol::bytes_per_pixel(t.format))));
  m.end = next;
  if (m.end > vram_bytes)
    return make_error(fmt::format("{}: the framebuffer, depth buffer and textures need {} bytes of video memory; the "
                                  "device has {} (use smaller or fewer textures, or a smaller framebuffer)",
                                  scene.name, m.end, vram_bytes));
  return m;
}

Result<BuiltScene> build_commands(const Scene& scene, const BuildOptions& options) {
  BuiltScene out;
  out.width = scene.width;
  out.height = scene.height;
  out.format = scene.format;
  auto layout = plan_memory(scene, options.vram_bytes);
  if (!layout) return layout.error();
  out.layout = *layout;
  // The scene name is a file path, which need not be UTF-8: json_text replaces bad bytes.
  out.stream.metadata_json = json_text(nlohmann::json{{"created_by", "gpubridge scene loader"},
                                                      {"scene", scene.name},
                                                      {"width", scene.width},
                                                      {"height", scene.height},
                                                      {"format", protocol::to_string(scene.format)}});
  protocol::CommandStreamWriter w(out.stream);

  // Setup: buffers, full scissor, clears.
  auto fb = in_scene(scene, geometry::fb_format_word(scene.width, scene.height, scene.format));
  if (!fb) return fb.error();
  w.write(Reg::FB_FORMAT, *fb);
  w.write(Reg::FB_DRAW, out.layout.color);
  if (out.layout.depth) w.write(Reg::FB_Z, *out.layout.depth);
  const std::uint64_t full_scissor = *geometry::scissor_word(0, 0, protocol::kMaxFramebufferDim, protocol::kMaxFramebufferDim);
  w.write(Reg::SCISSOR, full_scissor);
  auto clear_rgba = in_scene(scene, geometry::color_to_rgba8(scene.clear_color));
  if (!clear_rgba) return clear_rgba.error();
  w.write(Reg::CLEAR_COLOR, *clear_rgba);
  w.write(Reg::CLEAR, 0);
  if (out.layout.depth) {
    auto z = in_scene(scene, geometry::depth_to_z24(scene.clear_depth));
    if (!z) return z.error();
    w.write(Reg::CLEAR_DEPTH, *z);
    w.write(Reg::CLEAR_Z, 0);
  }

  // Textures, converted to their device format.
  for (std::size_t t = 0; t < scene.textures.size(); ++t)
    w.upload(out.layout.textures[t], device_from_image(scene.textures[t].format, scene.textures[t].image));

  // Draws. State registers are written only when they change.
  std::optional<std::uint64_t> tri_mode, tex_base, tex_fmt;
  std::uint64_t scissor = full_scissor;
  std::vector<geometry::DeviceTriangle> tris;
  for (std::size_t di = 0; di < scene.draws.size(); ++di) {
    const Draw& d = scene.draws[di];
    const std::string where = fmt::format("{}: draws[{}]", scene.name, di);
    geometry::PipelineOptions opt;
    opt.cull = d.cull;
    opt.textured = d.state.textured;
    const std::uint64_t mode = geometry::tri_mode_word(d.state);
    if (tri_mode != mode) w.write(Reg::TRI_MODE, mode);
    tri_mode = mode;
    if (d.texture) {
      const Texture& tex = scene.textures[*d.texture];
      geometry::TextureFormat tf{tex.image.width, tex.image.height, tex.format, d.wrap_s.value_or(tex.wrap_s),
                                 d.wrap_t.value_or(tex.wrap_t), d.bilinear.value_or(tex.bilinear)};
      opt.tex = {tf.wrap_s, tf.wrap_t};
      opt.texture_size = std::max(tf.width, tf.height);
      auto fmt_word = geometry::tex_fmt_word(tf);
      if (!fmt_word) return make_error(fmt::format("{}: {}", where, fmt_word.error().message));
      const std::uint64_t base = out.layout.textures[*d.texture];
      if (tex_base != base) w.write(Reg::TEX_BASE, base);
      if (tex_fmt != *fmt_word) w.write(Reg::TEX_FMT, *fmt_word);
      tex_base = base;
      tex_fmt = *fmt_word;
    }
    std::uint64_t sc = full_scissor;
    if (d.scissor) {
      auto s = geometry::scissor_word((*d.scissor)[0], (*d.scissor)[1], (*d.scissor)[2], (*d.scissor)[3]);
      if (!s) return make_error(fmt::format("{}.scissor: {}", where, s.error().message));
      sc = *s;
    }
    if (sc != scissor) w.write(Reg::SCISSOR, sc);
    scissor = sc;
    w.write(Reg::PRIM, static_cast<unsigned>(protocol::PrimType::List));
    for (std::size_t v = 0; v + 2 < d.vertices.size(); v += 3) {
      tris.clear();
      auto r = geometry::process_screen_triangle({d.vertices[v], d.vertices[v + 1], d.vertices[v + 2]}, opt, tris,
                                                 &out.stats);
      if (!r)
        return make_error(fmt::format("{}.vertices[{}..{}] (triangle {}): {}", where, v, v + 2, v / 3, r.error().message));
      for (const auto& t : tris) geometry::encode_triangle(t, d.state.textured, w.frames());
    }
  }
  // Swap: scans out the finished frame.
  w.write(Reg::FB_DISPLAY, out.layout.color);
  w.flush();
  return out;
}

Result<BuiltScene> load_scene(const std::filesystem::path& path, const BuildOptions& options, const Limits& limits) {
  auto scene = read_scene_file(path, limits);
  if (!scene) return scene.error();
  return build_commands(*scene, options);
}

}  // namespace gpubridge::scene
