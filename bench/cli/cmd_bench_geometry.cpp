// `gpubridge bench geometry`: host geometry pipeline throughput (transform, clip, snap, S/T/Q
// normalisation, register encoding) on fixed workloads, and, per example scene, what one frame
// costs: triangles, register frames, bytes, host time, simulator time and the frame rate the SPI
// link allows at a given clock.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include <nlohmann/json.hpp>

#include "bench_group.hpp"
#include "command.hpp"
#include "gpubridge/common/json_text.hpp"
#include "gpubridge/draw/sim_sink.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/geometry/geometry.hpp"

namespace gpubridge::cli {
namespace {

using Clock = std::chrono::steady_clock;
using namespace geometry;

struct Workload {
  std::string name, what;
  std::vector<Triangle> triangles;
  PipelineOptions options;
};

Vertex screen_vertex(double x, double y, double z, double w, Vec2 uv = {}) {
  ScreenVertex s;
  s.x = x;
  s.y = y;
  s.z = z;
  s.w = w;
  s.uv = uv;
  s.color = {0.2, 0.5, 0.8, 1};
  return from_screen(s);
}

std::vector<Workload> workloads(std::size_t n) {
  std::mt19937_64 rng(1234);
  std::uniform_real_distribution<double> pos(0, 620), jitter(-5, 5), unit(0, 1), far(-40000, 40000);
  std::vector<Workload> out;
  {
    Workload w{"small", "10-px² screen triangles inside the viewport, untextured", {}, {}};
    for (std::size_t i = 0; i < n; ++i) {
      const double x = pos(rng), y = pos(rng) * 0.75;
      w.triangles.push_back({screen_vertex(x, y, 0.5, 1), screen_vertex(x + 5, y, 0.5, 1), screen_vertex(x, y + 4, 0.5, 1)});
    }
    out.push_back(std::move(w));
  }
  {
    Workload w{"textured", "perspective textured triangles (W ratio ≤ 4, UV extent ≤ 1): no subdivision", {}, {}};
    w.options.textured = true;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = pos(rng), y = pos(rng) * 0.75;
      w.triangles.push_back({screen_vertex(x, y, unit(rng), 1 + 3 * unit(rng), {unit(rng), unit(rng)}),
                             screen_vertex(x + 20, y, unit(rng), 1 + 3 * unit(rng), {unit(rng), unit(rng)}),
                             screen_vertex(x, y + 20, unit(rng), 1 + 3 * unit(rng), {unit(rng), unit(rng)})});
    }
    out.push_back(std::move(w));
  }
  {
    Workload w{"near-clip", "3D triangles crossing the near plane (perspective camera)", {}, {}};
    const Mat4 m = viewport_matrix({0, 0, 640, 480}) * perspective(1.0, 4.0 / 3, 0.1, 100);
    std::uniform_real_distribution<double> c(-3, 3), z(-2, 1);
    for (std::size_t i = 0; i < n; ++i) {
      Triangle t;
      for (auto& v : t) v.pos = m * Vec4{c(rng), c(rng), z(rng), 1};
      t[0].pos = m * Vec4{c(rng), c(rng), 0.5, 1};    // behind the eye
      t[1].pos = m * Vec4{c(rng), c(rng), -3, 1};     // in front
      w.triangles.push_back(t);
    }
    out.push_back(std::move(w));
  }
  {
    Workload w{"guard-band", "huge screen triangles clipped to the 12.4 guard band", {}, {}};
    for (std::size_t i = 0; i < n; ++i)
      w.triangles.push_back({screen_vertex(far(rng), far(rng), 0.5, 1), screen_vertex(far(rng), far(rng), 0.5, 1),
                             screen_vertex(pos(rng), pos(rng), 0.5, 1)});
    out.push_back(std::move(w));
  }
  {
    Workload w{"subdivide", "grazing textured floor triangles (W 1..200, UV extent 16): precision subdivision", {}, {}};
    w.options.textured = true;
    w.options.max_subdivision_depth = 8;
    for (std::size_t i = 0; i < n / 16; ++i) {
      const double x = pos(rng) * 0.5;
      w.triangles.push_back({screen_vertex(x, 470, 0.1, 1, {0, 0}), screen_vertex(x + 300, 470, 0.1, 1, {16, 0}),
                             screen_vertex(x + 150, 200, 0.9, 200, {8, 16})});
    }
    out.push_back(std::move(w));
  }
  return out;
}

int run(const GlobalOptions& g, unsigned triangles, unsigned runs, double spi_mhz) {
  nlohmann::json report;
  report["triangles_per_workload"] = triangles;
  report["runs"] = runs;
  report["spi_mhz"] = spi_mhz;
  if (!g.json)
    std::printf("host geometry pipeline (best of %u runs, %u triangles per workload, one thread)\n\n"
                "| workload | Mtri/s in | out/in | frames/tri | what |\n|---|---|---|---|---|\n",
                runs, triangles);
  std::vector<DeviceTriangle> out;
  std::vector<protocol::Frame> frames;
  for (auto& w : workloads(triangles)) {
    double best = 1e30;
    PipelineStats st;
    for (unsigned r = 0; r < runs; ++r) {
      out.clear();
      frames.clear();
      st = {};
      const auto t0 = Clock::now();
      for (const auto& t : w.triangles)
        if (auto res = process_triangle(t, w.options, out, &st); !res) {
          std::fprintf(stderr, "gpubridge bench geometry: %s: %s\n", w.name.c_str(), res.error().message.c_str());
          return 1;
        }
      for (const auto& t : out) encode_triangle(t, w.options.textured, frames);
      best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
    }
    const double mtri = w.triangles.size() / best / 1e6;
    const double ratio = static_cast<double>(st.emitted) / w.triangles.size();
    const double fpt = out.empty() ? 0 : static_cast<double>(frames.size()) / out.size();
    report["workloads"].push_back({{"name", w.name}, {"what", w.what}, {"triangles_in", w.triangles.size()},
                                   {"triangles_out", st.emitted}, {"seconds", best}, {"mtri_per_s", mtri},
                                   {"frames_per_triangle", fpt}, {"subdivided", st.subdivided},
                                   {"clipped", st.clipped}, {"culled", st.culled}});
    if (!g.json) std::printf("| %s | %.2f | %.2f | %.1f | %s |\n", w.name.c_str(), mtri, ratio, fpt, w.what.c_str());
  }
  if (!g.json)
    std::printf("\nexample scenes, per frame (frame %u; SPI fps = link limit for the frame's register bytes at %.0f MHz, "
                "72 bits per frame)\n\n| example | triangles | frames | KiB | host ms | sim ms | SPI fps |\n"
                "|---|---|---|---|---|---|---|\n",
                examples::kGoldenFrame, spi_mhz);
  for (auto& ex : examples::make_examples()) {
    const std::string name = ex->info().name;
    // Host side alone: record the frame's commands.
    double host = 1e30, sim_time = 1e30;
    std::size_t frame_count = 0;
    std::size_t tris = 0;
    for (unsigned r = 0; r < runs; ++r) {
      draw::RecordingSink rec;
      auto ctx = draw::Context::create(rec, ex->options());
      if (!ctx || !ex->setup(*ctx)) return 1;
      const std::size_t before = rec.stream().commands.size();
      const auto emitted_before = ctx->stats().emitted;
      const auto t0 = Clock::now();
      if (!ex->frame(*ctx, examples::kGoldenFrame) || !ctx->swap()) return 1;
      host = std::min(host, std::chrono::duration<double>(Clock::now() - t0).count());
      frame_count = 0;
      for (std::size_t i = before; i < rec.stream().commands.size(); ++i) {
        const auto& cmd = rec.stream().commands[i].command;
        if (const auto* f = std::get_if<protocol::FramesCmd>(&cmd)) frame_count += f->size();
        // A texture upload on the link: MEM_ADDR, then one MEM_DATA frame per 8 bytes.
        if (const auto* u = std::get_if<protocol::UploadCmd>(&cmd)) frame_count += 1 + (u->data.size() + 7) / 8;
      }
      tris = ctx->stats().emitted - emitted_before;
      // Host + simulator.
      auto sink = draw::SimulatorSink::create();
      if (!sink) return 1;
      auto sctx = draw::Context::create(**sink, ex->options());
      if (!sctx || !ex->setup(*sctx)) return 1;
      const auto t1 = Clock::now();
      if (!ex->frame(*sctx, examples::kGoldenFrame) || !sctx->swap() || !sctx->flush()) return 1;
      sim_time = std::min(sim_time, std::chrono::duration<double>(Clock::now() - t1).count());
    }
    const double bytes = frame_count * 9.0;
    const double spi_fps = spi_mhz * 1e6 / (frame_count * 72.0);
    report["examples"].push_back({{"name", name}, {"triangles", tris}, {"frames", frame_count}, {"bytes", bytes},
                                  {"host_ms", host * 1e3}, {"host_plus_sim_ms", sim_time * 1e3}, {"spi_fps", spi_fps}});
    if (!g.json)
      std::printf("| %s | %zu | %zu | %.1f | %.2f | %.2f | %.1f |\n", name.c_str(), tris, frame_count, bytes / 1024,
                  host * 1e3, sim_time * 1e3, spi_fps);
  }
  if (g.json) std::puts(json_text(report, 2).c_str());
  return 0;
}

void setup(CLI::App& parent, GlobalOptions& g, std::vector<std::pair<CLI::App*, Runner>>& runners) {
  auto* sub = parent.add_subcommand("geometry", "host geometry pipeline throughput and per-example frame costs");
  auto triangles = std::make_shared<unsigned>(200000);
  auto runs = std::make_shared<unsigned>(3);
  auto mhz = std::make_shared<double>(25.0);
  sub->add_option("--triangles", *triangles, "triangles per workload")->check(CLI::Range(16u, 10000000u))->capture_default_str();
  sub->add_option("--runs", *runs, "repetitions; the best is reported")->check(CLI::Range(1u, 100u))->capture_default_str();
  sub->add_option("--spi-mhz", *mhz, "SPI clock for the link-limited frame rate")->check(CLI::Range(0.1, 1000.0))->capture_default_str();
  runners.emplace_back(sub, [&g, triangles, runs, mhz] { return run(g, *triangles, *runs, *mhz); });
}

}  // namespace

GPUBRIDGE_COMMAND("bench-geometry", 81, [](CLI::App& app, GlobalOptions& g, auto& runners) { setup(*bench_group(app), g, runners); });

}  // namespace gpubridge::cli
