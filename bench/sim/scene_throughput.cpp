// scene_throughput: one scene of `gpubridge bench accuracy` (bench/src/scenes.cpp) written to the
// simulator device exactly as its throughput rows write it (bench/src/sim_runner.cpp: the same
// device set-up and the same frame: CLEAR + CLEAR_Z + the whole scene), without the rest of the
// report. For instruction counts (valgrind --tool=callgrind) and alternating timings of one row,
// where sim_throughput's triangles (equilateral, one size) are not the scene's (random shapes).
//
// Usage: scene_throughput --scene NAME [--threads N] [--repeat R] [--accuracy KNOB=VALUE]...
// Prints the best wall time of R frames (after a warm-up frame), the process CPU time of the best
// frame and the CRC of video memory after the last frame (the bytes; the same for any thread count).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "gpubridge/accuracy/texel_probe.hpp"
#include "gpubridge/bench/scenes.hpp"
#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/sim/device.hpp"
#include "gpubridge/sim/options.hpp"

using namespace gpubridge;
using protocol::Reg;

namespace {

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + double(ts.tv_nsec) * 1e-9;
}

std::vector<std::uint8_t> to_bytes(const std::vector<protocol::Frame>& frames) {
  std::vector<std::uint8_t> bytes;
  bytes.reserve(frames.size() * protocol::kFrameBytes);
  for (const auto& f : frames) protocol::append(bytes, f);
  return bytes;
}

// sim_runner.cpp's layout: colour at 0, depth after it, the texture after that (16-byte aligned).
struct Layout {
  std::uint32_t color = 0, depth = 0, texture = 0;
};
Layout layout_of(const bench::Scene& s) {
  Layout l;
  l.depth = (s.width * s.height * 4 + 15) & ~15u;
  l.texture = l.depth + ((s.width * s.height * 4 + 15) & ~15u);
  return l;
}

// sim_runner.cpp's make_device set-up frames (the probe texture is copied in by the caller).
Result<std::vector<std::uint8_t>> setup_bytes(const bench::Scene& s) {
  const Layout l = layout_of(s);
  std::vector<protocol::Frame> f;
  auto word = [&](Reg r, Result<std::uint64_t> w) -> Result<void> {
    if (!w) return w.error();
    f.push_back(protocol::write_frame(r, *w));
    return {};
  };
  if (auto r = word(Reg::FB_FORMAT, geometry::fb_format_word(s.width, s.height, protocol::PixelFormat::RGBA8888)); !r) return r.error();
  if (auto r = word(Reg::FB_DRAW, geometry::address16_word(l.color)); !r) return r.error();
  if (auto r = word(Reg::FB_Z, geometry::address16_word(l.depth)); !r) return r.error();
  if (auto r = word(Reg::SCISSOR, geometry::scissor_word(0, 0, 1024, 1024)); !r) return r.error();
  if (s.textured) {
    if (auto r = word(Reg::TEX_BASE, geometry::address16_word(l.texture)); !r) return r.error();
    geometry::TextureFormat tf{.width = 1u << bench::kTextureLog2, .height = 1u << bench::kTextureLog2, .bilinear = true};
    if (auto r = word(Reg::TEX_FMT, geometry::tex_fmt_word(tf)); !r) return r.error();
  }
  return to_bytes(f);
}

// sim_runner.cpp's scene_frame: clear + state + every triangle.
std::vector<std::uint8_t> scene_bytes(const bench::Scene& s) {
  std::vector<protocol::Frame> f;
  f.reserve(s.triangles.size() * 9 + 8);
  f.push_back(protocol::write_frame(Reg::CLEAR_COLOR, 0x000000FF));
  f.push_back(protocol::write_frame(Reg::CLEAR, 0));
  f.push_back(protocol::write_frame(Reg::CLEAR_DEPTH, 0xFFFFFF));
  f.push_back(protocol::write_frame(Reg::CLEAR_Z, 0));
  f.push_back(protocol::write_frame(Reg::TRI_MODE, geometry::tri_mode_word(s.state)));
  f.push_back(protocol::write_frame(Reg::PRIM, static_cast<std::uint64_t>(protocol::PrimType::List)));
  for (const auto& t : s.triangles) geometry::encode_triangle(t, s.textured, f);
  return to_bytes(f);
}

}  // namespace

int main(int argc, char** argv) {
  sim::DeviceOptions opt;
  opt.vram_bytes = 16u << 20;  // as sim_runner.cpp
  unsigned repeat = 3;
  std::string name;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--scene") && i + 1 < argc) name = argv[++i];
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) opt.threads = static_cast<unsigned>(std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = static_cast<unsigned>(std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--accuracy") && i + 1 < argc) {
      if (auto r = sim::apply_knob(opt.accuracy, argv[++i]); !r) {
        std::fprintf(stderr, "scene_throughput: %s\n", r.error().message.c_str());
        return 2;
      }
    } else {
      std::fprintf(stderr, "usage: scene_throughput --scene NAME [--threads N] [--repeat R] [--accuracy KNOB=VALUE]...\n");
      return 2;
    }
  }
  auto scenes = bench::make_scenes(1);
  if (!scenes) return std::fprintf(stderr, "scene_throughput: %s\n", scenes.error().message.c_str()), 1;
  const auto it = std::find_if(scenes->begin(), scenes->end(), [&](const bench::Scene& s) { return s.name == name; });
  if (it == scenes->end()) {
    std::fprintf(stderr, "scene_throughput: no scene '%s'; scenes:", name.c_str());
    for (const auto& s : *scenes) std::fprintf(stderr, " %s", s.name.c_str());
    std::fprintf(stderr, "\n");
    return 2;
  }
  const bench::Scene& scene = *it;
  auto dev = sim::Device::create(opt);
  if (!dev) return std::fprintf(stderr, "scene_throughput: %s\n", dev.error().message.c_str()), 1;
  if (scene.textured) {
    const auto tex = accuracy::make_probe_texture(bench::kTextureLog2, bench::kTextureLog2);
    auto mem = (*dev)->memory();
    std::copy(tex.begin(), tex.end(), mem.begin() + layout_of(scene).texture);
  }
  const auto setup = setup_bytes(scene);
  if (!setup) return std::fprintf(stderr, "scene_throughput: %s\n", setup.error().message.c_str()), 1;
  (*dev)->write(protocol::FrameView{*setup});
  const auto bytes = scene_bytes(scene);
  double best = 1e30, best_cpu = 1e30;
  for (unsigned r = 0; r <= repeat; ++r) {
    (*dev)->reset_stats();
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    (*dev)->write(protocol::FrameView{bytes});
    (*dev)->drain();
    (void)(*dev)->memory();  // completes the triangles the band workers still hold
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double c = cpu_seconds() - c0;
    if (r > 0 && s < best) best = s, best_cpu = c;  // frame 0 is the warm-up
    if (repeat == 0) best = s, best_cpu = c;
  }
  const auto mem = static_cast<const sim::Device&>(**dev).memory();
  std::printf("%s threads %u accuracy %s: best frame %.3f ms (cpu %.3f ms), %zu triangles, %.1f ns/tri, memory CRC %08x\n",
              scene.name.c_str(), opt.threads, sim::to_string(opt.accuracy).c_str(), best * 1e3, best_cpu * 1e3,
              scene.triangles.size(), best * 1e9 / double(std::max<std::size_t>(scene.triangles.size(), 1)),
              protocol::crc32(mem));
  return 0;
}
