// sim_throughput: the simulator's unit costs on the workloads of the rasterization reference
// sheet (section 5.3): 640x480 RGBA8888 + Z, N random Gouraud triangles of fixed area, depth test
// LESS, "front" order (every pixel passes and writes colour + Z). Frames are encoded before the
// clock starts; the timed part is command decode + setup + rasterisation (Device::write).
// Usage: sim_throughput [--threads N] [--repeat R] [--only 10|1000|50000] [--random-z] [--format rgba8888|rgb565|rgba2222]
//                       [--scalar] [--tri-mode WORD] [--accuracy KNOB=VALUE ...]
// The last column is a CRC of video memory after the run: it must not change when the code gets faster.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <time.h>

#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/sim/device.hpp"

using namespace gpubridge;
using protocol::Reg;

namespace {

// CPU time of the whole process (all threads): on a loaded machine wall time overstates the cost.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + double(ts.tv_nsec) * 1e-9;
}

std::vector<std::uint8_t> make_scene(unsigned count, double area, std::uint32_t seed, bool random_z,
                                     std::uint64_t tri_mode, unsigned format) {
  std::vector<std::uint8_t> out;
  auto put = [&](Reg r, std::uint64_t d) { protocol::append(out, protocol::write_frame(r, d)); };
  put(Reg::FB_FORMAT, (std::uint64_t{format} << 32) | (480ull << 16) | 640);
  put(Reg::FB_DRAW, 0);
  put(Reg::FB_Z, 0x200000);
  put(Reg::CLEAR, 0);
  put(Reg::CLEAR_Z, 0);
  put(Reg::TRI_MODE, tri_mode);
  put(Reg::PRIM, 0);
  std::mt19937 rng(seed);
  const double r = std::sqrt(4 * area / (3 * std::sqrt(3.0)));
  std::uniform_real_distribution<double> cx(r, 640 - r), cy(r, 480 - r), ang(0, 6.2831853);
  std::uniform_int_distribution<std::uint32_t> col(0, 0xFFFFFFFFu);
  for (unsigned i = 0; i < count; ++i) {
    const double x = cx(rng), y = cy(rng), a = ang(rng);
    const std::uint32_t z = random_z ? col(rng) & 0xFFFFFF
                                     : 0xFFFFFF - static_cast<std::uint32_t>(std::uint64_t{i} * 0xFFFFF0 / count) - 1;
    for (int k = 0; k < 3; ++k) {
      const double t = a + k * 2.0943951;
      const int vx = static_cast<int>(std::lround((x + r * std::cos(t)) * 16));
      const int vy = static_cast<int>(std::lround((y + r * std::sin(t)) * 16));
      put(Reg::COLOR, (0xFFFFFFFFull << 32) | col(rng));
      put(Reg::VERTEX, (std::uint64_t{z} << 32) | (std::uint64_t{static_cast<std::uint16_t>(vy)} << 16) |
                           static_cast<std::uint16_t>(vx));
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  sim::DeviceOptions opt;
  unsigned repeat = 5;
  std::string only;  // "10", "1000" or "50000": run one workload
  std::uint64_t tri_mode = 1 | 4 | (1u << 3) | (1u << 6);  // Gouraud, Z test LESS, Z write (--tri-mode to change)
  bool random_z = false;  // --random-z: random depth per triangle (most pixels fail LESS) instead of front to back
  unsigned format = 0;    // --format rgba8888|rgb565|rgba2222: the framebuffer's pixel format (FB_FORMAT.FORMAT)
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) opt.threads = static_cast<unsigned>(std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
    else if (!std::strcmp(argv[i], "--random-z")) random_z = true;
    else if (!std::strcmp(argv[i], "--scalar")) opt.vector_routines = false;  // the reference routines only
    else if (!std::strcmp(argv[i], "--format") && i + 1 < argc) {
      const std::string f = argv[++i];
      if (f == "rgba8888") format = 0;
      else if (f == "rgb565") format = 1;
      else if (f == "rgba2222") format = 2;
      else return std::fprintf(stderr, "sim_throughput: --format %s: expected rgba8888, rgb565 or rgba2222\n", f.c_str()), 2;
    }
    else if (!std::strcmp(argv[i], "--tri-mode") && i + 1 < argc) tri_mode = std::strtoull(argv[++i], nullptr, 0);
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = static_cast<unsigned>(std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--accuracy") && i + 1 < argc) {
      if (auto r = sim::apply_knob(opt.accuracy, argv[++i]); !r) {
        std::fprintf(stderr, "sim_throughput: %s\n", r.error().message.c_str());
        return 2;
      }
    } else {
      std::fprintf(stderr, "usage: sim_throughput [--threads N] [--repeat R] [--only 10|1000|50000] [--random-z] [--format F] [--scalar] [--tri-mode WORD] [--accuracy KNOB=VALUE]...\n");
      return 2;
    }
  }
  struct Work {
    const char* name;
    unsigned count;
    double area;
  } const works[] = {{"10 px", 500000, 10}, {"1000 px", 50000, 1000}, {"50000 px", 2000, 50000}};
  std::printf("threads %u, accuracy %s, format %s, %s routines\n", opt.threads, sim::to_string(opt.accuracy).c_str(),
              format == 0 ? "rgba8888" : format == 1 ? "rgb565" : "rgba2222", opt.vector_routines ? "vector" : "scalar");
  std::printf("Wall-clock rates; cpu columns are process CPU time (all threads) per unit.\n");
  std::printf("| workload | triangles | Mtri/s | Mpix/s | ns/tri | ns/px | cpu ns/tri | cpu ns/px | memory CRC |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& w : works) {
    if (!only.empty() && std::to_string(static_cast<int>(w.area)) != only) continue;
    const auto frames = make_scene(w.count, w.area, 1, random_z, tri_mode, format);
    double best = 1e30, best_cpu = 1e30;
    std::uint64_t pixels = 0;
    std::uint32_t crc = 0;
    for (unsigned rep = 0; rep < repeat; ++rep) {
      auto dev = sim::Device::create(opt);
      if (!dev) return std::fprintf(stderr, "sim_throughput: %s\n", dev.error().message.c_str()), 1;
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = cpu_seconds();
      (*dev)->write(protocol::FrameView{frames});
      (void)(*dev)->memory();  // completes batched work
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      best = std::min(best, s);
      best_cpu = std::min(best_cpu, cpu_seconds() - c0);
      pixels = (*dev)->stats().pixels_depth_passed;
      crc = protocol::crc32((*dev)->memory());
    }
    std::printf("| %s | %u | %.3f | %.1f | %.1f | %.3f | %.1f | %.3f | %08x |\n", w.name, w.count, w.count / best / 1e6,
                pixels / best / 1e6, best * 1e9 / w.count, best * 1e9 / double(pixels), best_cpu * 1e9 / w.count,
                best_cpu * 1e9 / double(pixels), crc);
  }
  return 0;
}
