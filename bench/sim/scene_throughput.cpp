// scene_throughput: one scene of `gpubridge bench accuracy` (bench/src/scenes.cpp) written to the
// simulator device exactly as its throughput rows write it (the same device set-up and the same
// frame, CLEAR + CLEAR_Z + the whole scene: gpubridge/bench/sim_scene.hpp), without the rest of the
// report. For instruction counts (valgrind --tool=callgrind) and alternating timings of one row,
// where sim_throughput's triangles (equilateral, one size) are not the scene's (random shapes).
//
// Usage: scene_throughput --scene NAME [--threads N] [--repeat R] [--accuracy KNOB=VALUE]...
// Prints the best wall time of R frames (after a warm-up frame), the process CPU time of the best
// frame, the least CPU time of the calling thread over the frames (with N > 1 threads the device's
// front end) and the CRC of video memory after the last frame (the bytes; the same for any thread count).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "gpubridge/bench/scenes.hpp"
#include "gpubridge/bench/sim_scene.hpp"
#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/sim/device.hpp"
#include "gpubridge/sim/options.hpp"

using namespace gpubridge;

namespace {

double cpu_seconds(clockid_t clock = CLOCK_PROCESS_CPUTIME_ID) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return double(ts.tv_sec) + double(ts.tv_nsec) * 1e-9;
}

}  // namespace

int main(int argc, char** argv) {
  sim::DeviceOptions opt;  // threads and accuracy; the device is the bench's (sim_scene.hpp)
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
    } else if (!std::strcmp(argv[i], "--help")) {
      std::printf("usage: scene_throughput --scene NAME [--threads N] [--repeat R] [--accuracy KNOB=VALUE]...\n"
                  "One scene of `gpubridge bench accuracy` written to the simulator as its throughput rows write\n"
                  "it; prints the best frame's wall and CPU time and the CRC of video memory.\n");
      return 0;
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
  auto dev = bench::make_scene_device(scene, opt.accuracy, opt.threads);
  if (!dev) return std::fprintf(stderr, "scene_throughput: %s\n", dev.error().message.c_str()), 1;
  const auto bytes = bench::scene_frame_bytes(scene, scene.state, scene.triangles.size());
  // The calling thread's CPU time too: with N > 1 it is the device's front end (decode, FIFO,
  // setup), the critical path of small triangles, and unlike the wall time it hardly moves with
  // the machine's load.
  double best = 1e30, best_cpu = 1e30, best_front = 1e30;
  for (unsigned r = 0; r <= repeat; ++r) {
    (*dev)->reset_stats();
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds(), f0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
    (*dev)->write(protocol::FrameView{bytes});
    (*dev)->drain();
    (void)(*dev)->memory();  // completes the triangles the band workers still hold
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double c = cpu_seconds() - c0, f = cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - f0;
    if (r > 0 && s < best) best = s, best_cpu = c;  // frame 0 is the warm-up
    if (repeat == 0) best = s, best_cpu = c;
    if (r > 0 || repeat == 0) best_front = std::min(best_front, f);
  }
  const auto mem = static_cast<const sim::Device&>(**dev).memory();
  std::printf("%s threads %u accuracy %s: best frame %.3f ms (cpu %.3f ms, calling thread %.3f ms), %zu triangles, %.1f "
              "ns/tri, memory CRC %08x\n",
              scene.name.c_str(), opt.threads, sim::to_string(opt.accuracy).c_str(), best * 1e3, best_cpu * 1e3,
              best_front * 1e3,
              scene.triangles.size(), best * 1e9 / double(std::max<std::size_t>(scene.triangles.size(), 1)),
              protocol::crc32(mem));
  return 0;
}
