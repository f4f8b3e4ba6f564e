// Simulator side of the bench: everything goes through register frames, as from a client.
#include "sim_runner.hpp"

#include <chrono>

#include "gpubridge/accuracy/texel_probe.hpp"
#include "gpubridge/bench/sim_scene.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/sim/device.hpp"

namespace gpubridge::bench {
namespace {

using protocol::Reg;

struct Layout {
  std::uint32_t color = 0, depth = 0, texture = 0;
};
Layout layout_of(const Scene& s) {
  Layout l;
  l.depth = (s.width * s.height * 4 + 15) & ~15u;
  l.texture = l.depth + ((s.width * s.height * 4 + 15) & ~15u);
  return l;
}

std::vector<std::uint8_t> frames_to_bytes(const std::vector<protocol::Frame>& frames) {
  std::vector<std::uint8_t> bytes;
  bytes.reserve(frames.size() * protocol::kFrameBytes);
  for (const auto& f : frames) protocol::append(bytes, f);
  return bytes;
}

}  // namespace

Result<std::unique_ptr<sim::Device>> make_scene_device(const Scene& s, const sim::AccuracyKnobs& knobs, unsigned threads) {
  sim::DeviceOptions opt;
  opt.vram_bytes = 16u << 20;
  opt.threads = threads;
  opt.accuracy = knobs;
  auto dev = sim::Device::create(opt);
  if (!dev) return dev.error();
  const Layout l = layout_of(s);
  std::vector<protocol::Frame> setup;
  auto word = [&](Reg r, Result<std::uint64_t> w) -> Result<void> {
    if (!w) return w.error();
    setup.push_back(protocol::write_frame(r, *w));
    return {};
  };
  if (auto r = word(Reg::FB_FORMAT, geometry::fb_format_word(s.width, s.height, protocol::PixelFormat::RGBA8888)); !r) return r.error();
  if (auto r = word(Reg::FB_DRAW, geometry::address16_word(l.color)); !r) return r.error();
  if (auto r = word(Reg::FB_Z, geometry::address16_word(l.depth)); !r) return r.error();
  if (auto r = word(Reg::SCISSOR, geometry::scissor_word(0, 0, 1024, 1024)); !r) return r.error();
  if (s.textured) {
    const auto tex = accuracy::make_probe_texture(kTextureLog2, kTextureLog2);
    // Direct memory access has the same effect as MEM_ADDR/MEM_DATA (sim/device.hpp).
    auto mem = (*dev)->memory();
    std::copy(tex.begin(), tex.end(), mem.begin() + l.texture);
    if (auto r = word(Reg::TEX_BASE, geometry::address16_word(l.texture)); !r) return r.error();
    geometry::TextureFormat tf{.width = 1u << kTextureLog2, .height = 1u << kTextureLog2, .bilinear = true};
    if (auto r = word(Reg::TEX_FMT, geometry::tex_fmt_word(tf)); !r) return r.error();
  }
  const auto bytes = frames_to_bytes(setup);
  (*dev)->write(protocol::FrameView{bytes});
  return dev;
}

std::vector<std::uint8_t> scene_frame_bytes(const Scene& s, const geometry::RenderState& st, std::size_t count) {
  std::vector<protocol::Frame> f;
  f.reserve(count * 9 + 8);
  f.push_back(protocol::write_frame(Reg::CLEAR_COLOR, 0x000000FF));
  f.push_back(protocol::write_frame(Reg::CLEAR, 0));
  f.push_back(protocol::write_frame(Reg::CLEAR_DEPTH, 0xFFFFFF));
  f.push_back(protocol::write_frame(Reg::CLEAR_Z, 0));
  f.push_back(protocol::write_frame(Reg::TRI_MODE, geometry::tri_mode_word(st)));
  f.push_back(protocol::write_frame(Reg::PRIM, static_cast<std::uint64_t>(protocol::PrimType::List)));
  for (std::size_t i = 0; i < count && i < s.triangles.size(); ++i) geometry::encode_triangle(s.triangles[i], s.textured, f);
  return frames_to_bytes(f);
}


Result<Timing> time_sim(const Scene& scene, const sim::AccuracyKnobs& knobs, unsigned threads, unsigned runs) {
  auto dev = make_scene_device(scene, knobs, threads);
  if (!dev) return dev.error();
  const auto bytes = scene_frame_bytes(scene, scene.state, scene.triangles.size());
  Timing t;
  t.best_seconds = 1e30;
  for (unsigned r = 0; r <= runs; ++r) {
    (*dev)->reset_stats();
    const auto t0 = std::chrono::steady_clock::now();
    (*dev)->write(protocol::FrameView{bytes});
    (*dev)->drain();
    (void)(*dev)->memory();  // completes the triangles the band workers still hold
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (r > 0) t.best_seconds = std::min(t.best_seconds, sec);  // run 0 is the warm-up
    t.pixels_covered = (*dev)->stats().pixels_covered;
  }
  return t;
}

Result<RenderedFrame> render_sim_error_pass(const Scene& scene, const sim::AccuracyKnobs& knobs) {
  auto dev_r = make_scene_device(scene, knobs, 1);
  if (!dev_r) return dev_r.error();
  auto& dev = **dev_r;
  const std::size_t n = std::size_t{scene.width} * scene.height;
  RenderedFrame out;
  out.count.assign(n, 0);
  out.owner.assign(n, -1);
  dev.set_pixel_observer([&](const sim::CoveredPixel& p) {
    if (p.x < 0 || p.y < 0 || unsigned(p.x) >= scene.width || unsigned(p.y) >= scene.height) return;
    const std::size_t i = std::size_t(p.y) * scene.width + std::size_t(p.x);
    out.count[i] += 1;
    out.owner[i] = std::max(out.owner[i], std::int64_t(p.triangle));
  });
  geometry::RenderState st;
  st.gouraud = true;
  st.z_test = true;
  st.z_func = protocol::DepthFunc::Always;
  st.z_write = true;
  st.textured = scene.textured;
  st.tex_decal = scene.textured;
  const auto bytes = scene_frame_bytes(scene, st, scene.error_subset);
  dev.write(protocol::FrameView{bytes});
  dev.drain();
  dev.set_pixel_observer(nullptr);
  const auto mem = static_cast<const sim::Device&>(dev).memory();
  const Layout l = layout_of(scene);
  out.rgba.assign(mem.begin() + l.color, mem.begin() + l.color + n * 4);
  out.depth.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* p = mem.data() + l.depth + i * 4;
    out.depth[i] = ((std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3]);
  }
  return out;
}

}  // namespace gpubridge::bench
