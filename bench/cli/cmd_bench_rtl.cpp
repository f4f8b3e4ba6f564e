// `gpubridge bench rtl`: every example (its golden frame) and every scene file on the gateware
// profiles through the board path (rtl:BOARD), with the simulator fed the same command stream:
// the RTL's cycles per frame against the timing model's prediction (docs/protocol.md section 19),
// before and after calibration, and the co-simulation's speed (simulated clocks/s, frames/s).
// --fit prints the least-squares timing parameters for a profile (what timing_preset() holds).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "bench_group.hpp"
#include "command.hpp"
#include "gpubridge/common/json_text.hpp"
#include "gpubridge/draw/context.hpp"
#include "gpubridge/draw/sink.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/rtl/rtl_device.hpp"
#include "gpubridge/rtl/simulator_options.hpp"
#include "gpubridge/scene/scene.hpp"
#include "gpubridge/sim/device.hpp"
#include "gpubridge/sim/timing.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "gpubridge/usb/emu/rtl_pins.hpp"

namespace gpubridge::cli {
namespace {

namespace fs = std::filesystem;

struct RtlBenchArgs {
  std::vector<std::string> profiles{"up5k", "ecp5"};
  bool fit = false;
  bool quick = false;
  std::string config_dir;
};

// One scanned-out frame measured on both sides.
struct Sample {
  std::string scene, profile;
  double rtl_cycles = 0;      // gateware clocks with work between the previous swap and this one
  sim::DeviceStats work;      // the simulator's counters for the same frame
  unsigned bpp = 4;
  double wall_s = 0;          // co-simulation time of the run
  double simulated_clocks = 0;
  unsigned frames = 0;
};

const char* board_of(const std::string& gw) { return gw == "up5k" ? "icebreaker" : "ulx3s"; }

// Plays `stream` on the gateware board and on a simulator with the same CAPS; one sample per frame.
Result<std::vector<Sample>> measure(const std::string& scene, const std::string& gw, const protocol::CommandStream& stream,
                                    const fs::path& config_dir) {
  auto profile = usb::find_board_profile(config_dir, board_of(gw));
  if (!profile) return profile.error();
  profile->scanout = usb::ScanoutMode::CrcOnly;
  usb::emu::EmulationOptions eo;
  eo.pins = usb::emu::rtl_pins();
  auto board = usb::emu::open_emulated_board(*profile, eo);
  if (!board) return board.error();
  rtl::RtlDevice& g = usb::emu::rtl_pins_of(*board->stack)->device();
  const auto o = rtl::simulator_options(g.caps());
  auto sim = sim::Device::create(o);
  if (!sim) return sim.error();

  std::vector<Sample> out;
  std::vector<double> rtl_frames;
  double last_work = double(g.counters().work_cycles);
  board->backend->set_scanout_callback([&](std::shared_ptr<const backends::ScanoutFrame>) {
    const double w = double(g.counters().work_cycles);
    rtl_frames.push_back(w - last_work);
    last_work = w;
  });
  std::vector<std::pair<sim::DeviceStats, unsigned>> sim_frames;
  sim::DeviceStats last;
  (*sim)->set_scanout_callback([&](std::shared_ptr<const backends::ScanoutFrame> f) {
    const auto now = (*sim)->stats();
    sim_frames.emplace_back(sim::stats_difference(now, last), protocol::bytes_per_pixel(f->format));
    last = now;
  });
  const double clocks0 = double(g.counters().cycles);
  const auto t0 = std::chrono::steady_clock::now();
  for (const auto& tc : stream.commands) {
    if (const auto* f = std::get_if<protocol::FramesCmd>(&tc.command)) {
      if (auto r = board->backend->write_frames(f->view()); !r) return r.error();
      (*sim)->write(f->view());
    } else if (const auto* u = std::get_if<protocol::UploadCmd>(&tc.command)) {
      const std::uint64_t vram = o.vram_bytes;
      if (u->address >= vram) continue;
      const auto n = std::min<std::uint64_t>(u->data.size(), vram - u->address);
      if (auto r = board->backend->upload(u->address, std::span(u->data).first(n)); !r) return r.error();
      auto m = (*sim)->memory();
      std::copy(u->data.begin(), u->data.begin() + static_cast<std::ptrdiff_t>(n), m.begin() + u->address);
    }
  }
  if (auto r = board->backend->flush(); !r) return r.error();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double clocks = double(g.counters().cycles) - clocks0;
  for (std::size_t i = 0; i < rtl_frames.size() && i < sim_frames.size(); ++i) {
    Sample s;
    s.scene = scene;
    s.profile = gw;
    s.rtl_cycles = rtl_frames[i];
    s.work = sim_frames[i].first;
    s.bpp = sim_frames[i].second;
    s.wall_s = wall;
    s.simulated_clocks = clocks;
    s.frames = unsigned(rtl_frames.size());
    out.push_back(s);
  }
  return out;
}

// The streams: each example's frames kGoldenFrame - 1 and kGoldenFrame (the second one is measured:
// the first carries the setup, uploads included), and every scene file.
Result<std::vector<std::pair<std::string, protocol::CommandStream>>> streams(bool quick) {
  std::vector<std::pair<std::string, protocol::CommandStream>> out;
  for (const auto& name : examples::example_names()) {
    if (quick && name != "cubes" && name != "tetrahedron") continue;
    auto ex = examples::make_example(name);
    draw::RecordingSink rec(8u << 20);
    auto ctx = draw::Context::create(rec, ex->options());
    if (!ctx) return ctx.error();
    if (auto r = examples::run_frames(*ex, *ctx, examples::kGoldenFrame - 1, 2); !r) return r.error();
    out.emplace_back(name, rec.take());
  }
  const fs::path dir = fs::path(GPUBRIDGE_SCENES_DIR);
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    if (quick) break;
    auto built = scene::load_scene(f, {.vram_bytes = 8u << 20});
    if (!built) return built.error();
    out.emplace_back(f.stem().string(), std::move(built->stream));
  }
  return out;
}

// Non-negative least squares on relative error: measured ≈ Σ p_j x_j, each row weighted 1/measured
// (projected gradient; the problem is tiny).
std::vector<double> fit_linear(const std::vector<std::vector<double>>& x, const std::vector<double>& y) {
  const std::size_t n = x.front().size();
  std::vector<double> p(n, 0.0), scale(n, 0.0);
  for (std::size_t r = 0; r < x.size(); ++r)
    for (std::size_t j = 0; j < n; ++j) scale[j] = std::max(scale[j], x[r][j] / y[r]);
  for (std::size_t j = 0; j < n; ++j) p[j] = scale[j] > 0 ? 0.1 / scale[j] : 0;
  for (int it = 0; it < 200000; ++it) {
    std::vector<double> grad(n, 0.0);
    for (std::size_t r = 0; r < x.size(); ++r) {
      double pred = 0;
      for (std::size_t j = 0; j < n; ++j) pred += p[j] * x[r][j];
      const double e = (pred - y[r]) / y[r];
      for (std::size_t j = 0; j < n; ++j) grad[j] += 2 * e * x[r][j] / y[r];
    }
    for (std::size_t j = 0; j < n; ++j)
      if (scale[j] > 0) p[j] = std::max(0.0, p[j] - 0.02 * grad[j] / (scale[j] * scale[j] * double(x.size())));
  }
  return p;
}

int run_bench_rtl(const GlobalOptions& g, const RtlBenchArgs& a) {
  if (!rtl::RtlDevice::available()) {
    std::fprintf(stderr, "gpubridge bench rtl: %s\n", rtl::RtlDevice::unavailable_reason().c_str());
    return 1;
  }
  const fs::path config_dir = a.config_dir.empty() ? usb::default_config_dir() : fs::path(a.config_dir);
  auto all = streams(a.quick);
  if (!all) {
    std::fprintf(stderr, "gpubridge bench rtl: %s\n", all.error().message.c_str());
    return 1;
  }
  nlohmann::json report = nlohmann::json::object();
  for (const auto& gw : a.profiles) {
    if (!rtl::parse_gateware_profile(gw)) {
      std::fprintf(stderr, "gpubridge bench rtl: --profile %s: expected up5k or ecp5\n", gw.c_str());
      return 2;
    }
    auto preset = sim::timing_preset(gw);
    auto before = sim::timing_preset("ecp5-50mhz");
    std::vector<Sample> samples;
    for (const auto& [name, stream] : *all) {
      auto s = measure(name, gw, stream, config_dir);
      if (!s) {
        std::fprintf(stderr, "gpubridge bench rtl: %s on %s: %s\n", name.c_str(), gw.c_str(), s.error().message.c_str());
        return 1;
      }
      if (!s->empty()) samples.push_back(s->back());  // the measured frame: the last one
    }
    nlohmann::json rows = nlohmann::json::array();
    if (!g.json)
      std::printf("%s (board %s): RTL cycles per frame vs the timing model; co-simulation speed\n"
                  "  %-20s %12s %12s %8s %12s %8s %12s %9s\n",
                  gw.c_str(), board_of(gw), "scene", "rtl cycles", "default", "error", "calibrated", "error", "clocks/s", "frames/s");
    double worst = 0;
    for (const auto& s : samples) {
      const double d = sim::estimate_timing(s.work, *before, s.bpp).board_cycles;
      const double c = sim::estimate_timing(s.work, *preset, s.bpp).board_cycles;
      const double ed = (d - s.rtl_cycles) / s.rtl_cycles * 100, ec = (c - s.rtl_cycles) / s.rtl_cycles * 100;
      worst = std::max(worst, std::fabs(ec));
      const double cps = s.simulated_clocks / s.wall_s, fps = s.frames / s.wall_s;
      rows.push_back({{"scene", s.scene}, {"rtl_cycles", s.rtl_cycles}, {"default_cycles", d}, {"default_error_pct", ed},
                      {"calibrated_cycles", c}, {"calibrated_error_pct", ec}, {"simulated_clocks_per_s", cps},
                      {"frames_per_s", fps}, {"triangles", s.work.triangles_rasterised}, {"pixels", s.work.pixels_covered}});
      if (!g.json)
        std::printf("  %-20s %12.0f %12.0f %+7.1f%% %12.0f %+7.1f%% %12.0f %9.2f\n", s.scene.c_str(), s.rtl_cycles, d, ed, c, ec,
                    cps, fps);
    }
    if (!g.json) std::printf("  worst calibrated error %.1f%%\n", worst);
    report[gw] = {{"board", board_of(gw)}, {"rows", rows}, {"worst_calibrated_error_pct", worst}};
    if (a.fit && samples.size() >= 2) {
      std::vector<std::vector<double>> x;
      std::vector<double> y;
      for (const auto& s : samples) {
        const auto& w = s.work;
        x.push_back({double(w.queued_executed), double(w.triangles_rasterised), double(w.pixels_scanned),
                     double(w.pixels_depth_passed), double(w.pixels_textured), double(w.pixels_blended), double(w.clear_bytes)});
        y.push_back(s.rtl_cycles);
      }
      const auto p = fit_linear(x, y);
      const char* names[] = {"cycles_per_command", "cycles_per_triangle", "cycles_per_scanned_pixel", "cycles_per_pixel",
                             "cycles_per_textured_pixel", "cycles_per_blended_pixel", "cycles_per_clear_byte"};
      nlohmann::json fit;
      for (std::size_t j = 0; j < p.size(); ++j) fit[names[j]] = p[j];
      // the fit as a profile (memory bound included), and its error on the same frames
      sim::BoardTiming fitted = *preset;
      fitted.cycles_per_command = p[0];
      fitted.cycles_per_triangle = p[1];
      fitted.cycles_per_scanned_pixel = p[2];
      fitted.cycles_per_pixel = p[3];
      fitted.cycles_per_textured_pixel = p[4];
      fitted.cycles_per_blended_pixel = p[5];
      fitted.clear_bytes_per_cycle = p[6] > 0 ? 1.0 / p[6] : 1e9;
      double worst_fit = 0;
      for (const auto& s : samples) {
        const double f = sim::estimate_timing(s.work, fitted, s.bpp).board_cycles;
        worst_fit = std::max(worst_fit, std::fabs((f - s.rtl_cycles) / s.rtl_cycles * 100));
      }
      fit["worst_error_pct"] = worst_fit;
      report[gw]["fit"] = fit;
      if (!g.json) {
        std::printf("  least-squares fit:");
        for (std::size_t j = 0; j < p.size(); ++j) std::printf(" %s=%.4g", names[j], p[j]);
        std::printf("\n  worst error with the fit %.1f%%\n", worst_fit);
      }
    }
  }
  if (g.json) std::puts(json_text(report, 2).c_str());
  return 0;
}

}  // namespace

GPUBRIDGE_COMMAND("bench-rtl", 63, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  auto a = std::make_shared<RtlBenchArgs>();
  auto* sub = bench_group(app)->add_subcommand(
      "rtl", "the gateware co-simulated: RTL cycles per frame of every example and scene against the timing model, "
             "before and after calibration, and the co-simulation's speed");
  sub->add_option("--profile", a->profiles, "gateware profiles to run (up5k, ecp5)")->capture_default_str();
  sub->add_flag("--fit", a->fit, "print the least-squares timing parameters (the calibration behind timing_preset)");
  sub->add_flag("--quick", a->quick, "two examples only (a smoke run)");
  sub->add_option("--config-dir", a->config_dir, "directory holding boards/");
  runners.emplace_back(sub, [&g, a] { return run_bench_rtl(g, *a); });
});

}  // namespace gpubridge::cli
