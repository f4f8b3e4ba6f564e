// `gpubridge bench rtl`: every example (its golden frame) and every scene file on the gateware
// profiles through the board path (rtl:BOARD), with the simulator fed the same command stream:
// the RTL's cycles per frame against the timing model's prediction (docs/protocol.md section 19),
// before and after calibration, and the co-simulation's speed (simulated clocks/s, frames/s).
// --fit adds calibration frames (rtl_calibration.hpp) and prints the staged least-squares fit of the
// model's gateware terms (rtl_fit.hpp): what timing_preset() holds.
// --fill measures the whole device's fill rate per scene class instead (rtl_fill.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

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
#include "rtl_calibration.hpp"
#include "rtl_fill.hpp"
#include "rtl_fit.hpp"

namespace gpubridge::cli {
namespace {

namespace fs = std::filesystem;

struct RtlBenchArgs {
  std::vector<std::string> profiles{"up5k", "ecp5"};
  bool fit = false;
  bool fill = false;
  bool quick = false;
  std::string config_dir;
  std::string save_rtl;  // --save-rtl-counters: the gateware's counters per stream, to replay
  std::string load_rtl;  // --rtl-counters: replay them instead of co-simulating (the model only)
};

// One scanned-out frame measured on both sides.
struct Sample {
  std::string scene, profile;
  double rtl_cycles = 0;      // gateware clocks with work between the previous swap and this one
  rtl::RtlCounters rtl;       // the gateware's counters for the frame (differences)
  sim::DeviceStats work;      // the simulator's counters for the same frame
  unsigned bpp = 4;
  double wall_s = 0;          // co-simulation time of the run
  double simulated_clocks = 0;
  unsigned frames = 0;
};

const char* board_of(const std::string& gw) { return gw == "up5k" ? "icebreaker" : "ulx3s"; }

// Both sides' counters of a frame (bench rtl --json): what a model is fitted on.
nlohmann::json counters_json(const sim::DeviceStats& w, const rtl::RtlCounters& r) {
  nlohmann::json modes = nlohmann::json::object();
  for (unsigned m = 0; m < sim::DeviceStats::kModeClasses; ++m)
    if (w.by_mode[m].triangles)
      modes[sim::mode_class_name(m)] = {{"triangles", w.by_mode[m].triangles}, {"rows", w.by_mode[m].rows},
                                         {"columns", w.by_mode[m].columns}, {"pixels", w.by_mode[m].pixels}};
  return {{"sim",
           {{"frames_received", w.frames_received}, {"queued_executed", w.queued_executed},
            {"triangles_kicked", w.triangles_kicked}, {"triangles_rasterised", w.triangles_rasterised},
            {"triangles_rejected", w.triangles_rejected}, {"pixels_scanned", w.pixels_scanned},
            {"pixels_covered", w.pixels_covered}, {"pixels_depth_passed", w.pixels_depth_passed},
            {"pixels_textured", w.pixels_textured}, {"pixels_blended", w.pixels_blended}, {"texel_bytes", w.texel_bytes},
            {"clears", w.clears}, {"clear_rows", w.clear_rows}, {"clear_pixels", w.clear_pixels},
            {"clear_bytes", w.clear_bytes}, {"mem_data_writes", w.mem_data_writes}, {"swaps", w.swaps},
            {"texel_footprint_bytes", w.texel_footprint_bytes}, {"texel_fetches", w.texel_fetches}, {"sdram_accesses", w.sdram_accesses}, {"row_opens", w.row_opens}, {"row_misses", w.row_misses}, {"textured_row_misses", w.textured_row_misses}, {"depth_tail_pixels", w.depth_tail_pixels}, {"by_mode", modes}}},
          {"rtl",
           {{"work_cycles", r.work_cycles}, {"commands", r.commands}, {"core_busy_cycles", r.core_busy_cycles},
            {"setup_cycles", r.setup_cycles}, {"raster_cycles", r.raster_cycles}, {"core_mem_stalls", r.core_mem_stalls},
            {"triangles", r.triangles}, {"pixels", r.pixels}, {"passed", r.passed}, {"textured", r.textured},
            {"refreshes", r.refreshes}}}};
}

// The gateware's counters of every frame of a stream, as --save-rtl-counters writes them.
nlohmann::json rtl_frames_json(const std::vector<rtl::RtlCounters>& frames) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : frames)
    out.push_back({r.cycles, r.work_cycles, r.commands, r.spi_frames, r.core_mem_stalls, r.triangles, r.pixels, r.passed,
                   r.textured, r.core_busy_cycles, r.setup_cycles, r.raster_cycles, r.refreshes, r.sdram_violations,
                   r.sck_edges_too_fast});
  return out;
}

std::vector<rtl::RtlCounters> rtl_frames_of(const nlohmann::json& j) {
  std::vector<rtl::RtlCounters> out;
  for (const auto& f : j) {
    rtl::RtlCounters r;
    std::uint64_t* fields[] = {&r.cycles, &r.work_cycles, &r.commands, &r.spi_frames, &r.core_mem_stalls,
                               &r.triangles, &r.pixels, &r.passed, &r.textured, &r.core_busy_cycles,
                               &r.setup_cycles, &r.raster_cycles, &r.refreshes, &r.sdram_violations,
                               &r.sck_edges_too_fast};
    for (std::size_t i = 0; i < std::size(fields) && i < f.size(); ++i) *fields[i] = f[i].get<std::uint64_t>();
    out.push_back(r);
  }
  return out;
}

// Plays `stream` on the gateware board and on a simulator with the same CAPS; one sample per frame.
// `recorded` (--rtl-counters): the gateware's counters of an earlier run of the same stream; the
// board is then not co-simulated (the timing model's counters are the simulator's alone), and
// `recorded` is filled with the frames' counters otherwise (--save-rtl-counters).
Result<std::vector<Sample>> measure(const std::string& scene, const std::string& gw, const protocol::CommandStream& stream,
                                    const fs::path& config_dir, nlohmann::json& recorded) {
  const bool replay = !recorded.is_null();
  std::optional<usb::emu::EmulatedBoard> board;
  rtl::RtlDevice* g = nullptr;
  if (!replay) {
    auto profile = usb::find_board_profile(config_dir, board_of(gw));
    if (!profile) return profile.error();
    profile->scanout = usb::ScanoutMode::CrcOnly;
    usb::emu::EmulationOptions eo;
    eo.pins = usb::emu::rtl_pins();
    auto opened = usb::emu::open_emulated_board(*profile, eo);
    if (!opened) return opened.error();
    board.emplace(std::move(*opened));
    g = &usb::emu::rtl_pins_of(*board->stack)->device();
  }
  const auto o = rtl::simulator_options(g ? g->caps() : rtl::caps_of(*rtl::parse_gateware_profile(gw)));
  auto sim = sim::Device::create(o);
  if (!sim) return sim.error();

  std::vector<Sample> out;
  std::vector<rtl::RtlCounters> rtl_frames;
  if (replay) {
    try {
      rtl_frames = rtl_frames_of(recorded);
    } catch (const nlohmann::json::exception& e) {
      return make_error("--rtl-counters: " + scene + ": " + e.what());
    }
  }
  rtl::RtlCounters last_rtl = g ? g->counters() : rtl::RtlCounters{};
  if (board)
    board->backend->set_scanout_callback([&](std::shared_ptr<const backends::ScanoutFrame>) {
      const rtl::RtlCounters now = g->counters();
      rtl_frames.push_back(now - last_rtl);
      last_rtl = now;
    });
  std::vector<std::pair<sim::DeviceStats, unsigned>> sim_frames;
  sim::DeviceStats last;
  (*sim)->set_scanout_callback([&](std::shared_ptr<const backends::ScanoutFrame> f) {
    const auto now = (*sim)->stats();
    sim_frames.emplace_back(sim::stats_difference(now, last), protocol::bytes_per_pixel(f->format));
    last = now;
  });
  const double clocks0 = g ? double(g->counters().cycles) : 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  for (const auto& tc : stream.commands) {
    if (const auto* f = std::get_if<protocol::FramesCmd>(&tc.command)) {
      if (board)
        if (auto r = board->backend->write_frames(f->view()); !r) return r.error();
      (*sim)->write(f->view());
    } else if (const auto* u = std::get_if<protocol::UploadCmd>(&tc.command)) {
      const std::uint64_t vram = o.vram_bytes;
      if (u->address >= vram) continue;
      const auto n = std::min<std::uint64_t>(u->data.size(), vram - u->address);
      if (board)
        if (auto r = board->backend->upload(u->address, std::span(u->data).first(n)); !r) return r.error();
      // the simulator gets what the board driver sends (MEM_ADDR, then MEM_DATA words; a partial
      // last word keeps the bytes in memory), so its counters see the upload as the gateware does
      const auto m = (*sim)->memory();
      std::vector<protocol::Frame> words{protocol::write_frame(protocol::Reg::MEM_ADDR, u->address)};
      for (std::uint64_t off = 0; off < n; off += 8) {
        std::uint64_t v = 0;
        for (std::uint64_t b = 0; b < 8; ++b) v = v << 8 | (off + b < n ? u->data[off + b] : m[u->address + off + b]);
        words.push_back(protocol::write_frame(protocol::Reg::MEM_DATA, v));
      }
      for (const auto& wf : words) (*sim)->write(wf);
    }
  }
  if (board)
    if (auto r = board->backend->flush(); !r) return r.error();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double clocks = g ? double(g->counters().cycles) - clocks0 : 0.0;
  if (replay)
    for (const auto& r : rtl_frames) clocks += double(r.cycles);
  else
    recorded = rtl_frames_json(rtl_frames);
  for (std::size_t i = 0; i < rtl_frames.size() && i < sim_frames.size(); ++i) {
    Sample s;
    s.scene = scene;
    s.profile = gw;
    s.rtl_cycles = double(rtl_frames[i].work_cycles);
    s.rtl = rtl_frames[i];
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

// --fill: pixels per device clock of each scene class (rtl_fill.hpp) and Mpixel/s at the core clock.
int run_bench_rtl_fill(const GlobalOptions& g, const RtlBenchArgs& a, const fs::path& config_dir) {
  nlohmann::json report = nlohmann::json::object();
  for (const auto& gw : a.profiles) {
    const auto profile = rtl::parse_gateware_profile(gw);
    const auto caps = rtl::caps_of(*profile);
    auto rows = measure_fill(*profile, a.quick, config_dir);
    if (!rows) {
      std::fprintf(stderr, "gpubridge bench rtl --fill: %s: %s\n", gw.c_str(), rows.error().message.c_str());
      return 1;
    }
    if (!g.json)
      std::printf("%s (board %s, %g MHz): whole-device fill, one rectangle as two triangles, device work clocks\n"
                  "  %-44s %9s %10s %8s %10s %7s %7s\n",
                  gw.c_str(), board_of(gw), caps.core_hz / 1e6, "scene class", "size", "clocks", "px/clk", "Mpixel/s",
                  "setup", "stalls");
    nlohmann::json out = nlohmann::json::array();
    for (const auto& r : *rows) {
      const double clocks = double(std::max<std::uint64_t>(r.draw_clocks, 1));
      out.push_back({{"name", r.name}, {"width", r.width}, {"height", r.height}, {"bytes_per_pixel", r.bytes_per_pixel},
                     {"depth", r.depth}, {"blend", r.blend}, {"textured", r.textured}, {"bilinear", r.bilinear},
                     {"pixels", r.pixels}, {"draw_clocks", r.draw_clocks}, {"core_busy_clocks", r.core_busy_clocks},
                     {"setup_clocks", r.setup_clocks}, {"mem_stall_clocks", r.mem_stall_clocks},
                     {"refreshes", r.refreshes}, {"bytes_compared", r.bytes_compared},
                     {"bytes_differing", r.bytes_differing}, {"px_per_clock", r.px_per_clock},
                     {"mpixel_per_s", r.mpixel_per_s}});
      if (!g.json)
        std::printf("  %-44s %4ux%-4u %10llu %8.3f %10.1f %6.1f%% %6.1f%%\n", r.name.c_str(), r.width, r.height,
                    static_cast<unsigned long long>(r.draw_clocks), r.px_per_clock, r.mpixel_per_s,
                    100 * double(r.setup_clocks) / clocks, 100 * double(r.mem_stall_clocks) / clocks);
      if (!g.json && r.bytes_differing)
        std::printf("    ^ %llu of %llu VRAM bytes differ from the simulator's\n",
                    static_cast<unsigned long long>(r.bytes_differing), static_cast<unsigned long long>(r.bytes_compared));
    }
    report[gw] = {{"board", board_of(gw)}, {"core_hz", caps.core_hz}, {"quick", a.quick}, {"rows", out}};
  }
  if (g.json) std::puts(json_text(report, 2).c_str());
  return 0;
}

int run_bench_rtl(const GlobalOptions& g, const RtlBenchArgs& a) {
  if (!rtl::RtlDevice::available()) {
    std::fprintf(stderr, "gpubridge bench rtl: %s\n", rtl::RtlDevice::unavailable_reason().c_str());
    return 1;
  }
  const fs::path config_dir = a.config_dir.empty() ? usb::default_config_dir() : fs::path(a.config_dir);
  for (const auto& gw : a.profiles)
    if (!rtl::parse_gateware_profile(gw)) {
      std::fprintf(stderr, "gpubridge bench rtl: --profile %s: expected up5k or ecp5\n", gw.c_str());
      return 2;
    }
  if (a.fill) return run_bench_rtl_fill(g, a, config_dir);
  auto all = streams(a.quick);
  if (!all) {
    std::fprintf(stderr, "gpubridge bench rtl: %s\n", all.error().message.c_str());
    return 1;
  }
  // the gateware's counters per profile and stream: replayed (--rtl-counters) or recorded
  nlohmann::json rtl_counters = nlohmann::json::object();
  if (!a.load_rtl.empty()) {
    std::ifstream in(a.load_rtl);
    rtl_counters = nlohmann::json::parse(in, nullptr, false);
    if (!in || rtl_counters.is_discarded() || !rtl_counters.is_object()) {
      std::fprintf(stderr, "gpubridge bench rtl: --rtl-counters %s: not a file --save-rtl-counters wrote\n", a.load_rtl.c_str());
      return 1;
    }
  }
  nlohmann::json report = nlohmann::json::object();
  for (const auto& gw : a.profiles) {
    auto preset = sim::timing_preset(gw);
    auto before = sim::timing_preset("ecp5-50mhz");
    // the measured frame of each stream: its last one, both sides' counters over the same work
    auto run = [&](const std::string& name, const protocol::CommandStream& stream, std::vector<Sample>& out) -> bool {
      nlohmann::json recorded;  // null: co-simulate
      if (!a.load_rtl.empty()) {
        if (!rtl_counters.contains(gw) || !rtl_counters[gw].contains(name)) {
          std::fprintf(stderr, "gpubridge bench rtl: --rtl-counters %s holds no %s on %s\n", a.load_rtl.c_str(), name.c_str(),
                       gw.c_str());
          return false;
        }
        recorded = rtl_counters[gw][name];
      }
      auto s = measure(name, gw, stream, config_dir, recorded);
      if (a.load_rtl.empty()) rtl_counters[gw][name] = recorded;
      if (!s) {
        std::fprintf(stderr, "gpubridge bench rtl: %s on %s: %s\n", name.c_str(), gw.c_str(), s.error().message.c_str());
        return false;
      }
      if (s->empty()) return true;
      const Sample& last = s->back();
      // Frames are paired by index (a board reports one swap per WRITE_FRAMES batch): both sides
      // must have drawn the same pixels, or the pair is not one frame.
      if (last.rtl.pixels != last.work.pixels_covered) {
        std::fprintf(stderr, "gpubridge bench rtl: %s on %s: the frames do not pair (RTL %llu pixels, simulator %llu)\n",
                     name.c_str(), gw.c_str(), static_cast<unsigned long long>(last.rtl.pixels),
                     static_cast<unsigned long long>(last.work.pixels_covered));
        return false;
      }
      out.push_back(last);
      return true;
    };
    std::vector<Sample> samples, calibration;
    for (const auto& [name, stream] : *all)
      if (!run(name, stream, samples)) return 1;
    if (a.fit) {
      const bool texturing = gw == "ecp5";  // CAPS.FEATURES bit 7 (docs/gateware.md, the profiles' CAPS)
      const bool depth = gw == "ecp5";      // CAPS2.FEATURES2 bit 0 (protocol 1.4)
      for (const auto& c : calibration_streams(texturing, depth))
        if (!run(c.name, c.stream, calibration)) return 1;
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
      // a replay (--rtl-counters) co-simulates nothing: no speed to report
      const bool timed = a.load_rtl.empty() && s.wall_s > 0;
      const double cps = timed ? s.simulated_clocks / s.wall_s : 0, fps = timed ? s.frames / s.wall_s : 0;
      rows.push_back({{"scene", s.scene}, {"rtl_cycles", s.rtl_cycles}, {"default_cycles", d}, {"default_error_pct", ed},
                      {"calibrated_cycles", c}, {"calibrated_error_pct", ec}, {"simulated_clocks_per_s", cps},
                      {"frames_per_s", fps}, {"triangles", s.work.triangles_rasterised}, {"pixels", s.work.pixels_covered},
                      {"counters", counters_json(s.work, s.rtl)}});
      if (!g.json)
        std::printf("  %-20s %12.0f %12.0f %+7.1f%% %12.0f %+7.1f%% %12.0f %9.2f\n", s.scene.c_str(), s.rtl_cycles, d, ed, c, ec,
                    cps, fps);
    }
    if (!g.json) std::printf("  worst calibrated error %.1f%%\n", worst);
    report[gw] = {{"board", board_of(gw)}, {"rows", rows}, {"worst_calibrated_error_pct", worst}};
    if (a.fit && samples.size() + calibration.size() >= 2) {
      std::vector<FitSample> fs;
      for (const auto* set : {&samples, &calibration})
        for (const auto& s : *set) fs.push_back({s.work, s.rtl, s.bpp});
      const TimingFit fit = fit_timing(fs, *preset);
      nlohmann::json params = nlohmann::json::object(), errors = nlohmann::json::array();
      for (const auto& [k, v] : fit.parameters) params[k] = v;
      double worst_fit = 0, worst_calibration = 0;
      for (const auto* set : {&samples, &calibration})
        for (const auto& s : *set) {
          const auto e = sim::estimate_timing(s.work, fit.timing, s.bpp);
          const double err = (e.board_cycles - s.rtl_cycles) / s.rtl_cycles * 100;
          double& worst_of_set = set == &samples ? worst_fit : worst_calibration;
          worst_of_set = std::max(worst_of_set, std::fabs(err));
          errors.push_back({{"scene", s.scene}, {"rtl_cycles", s.rtl_cycles}, {"fitted_cycles", e.board_cycles},
                            {"memory_bound", e.memory_cycles > e.pipeline_cycles}, {"error_pct", err},
                            {"counters", counters_json(s.work, s.rtl)}});
        }
      report[gw]["fit"] = {{"parameters", params}, {"rows", errors}, {"worst_error_pct", worst_fit},
                           {"worst_calibration_error_pct", worst_calibration}, {"calibration_frames", calibration.size()}};
      if (!g.json) {
        std::printf("  least-squares fit on %zu scenes and %zu calibration frames (settings of --board-timing):\n   ",
                    samples.size(), calibration.size());
        for (const auto& [k, v] : fit.parameters) std::printf(" %s=%.4g", k.c_str(), v);
        std::printf("\n  worst error with the fit: %.1f%% on the scenes, %.1f%% on the calibration frames\n", worst_fit,
                    worst_calibration);
      }
    }
  }
  if (!a.save_rtl.empty()) {
    std::ofstream out(a.save_rtl);
    out << rtl_counters.dump() << "\n";
    if (!out) {
      std::fprintf(stderr, "gpubridge bench rtl: --save-rtl-counters %s: cannot write\n", a.save_rtl.c_str());
      return 1;
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
  auto* fit = sub->add_flag("--fit", a->fit,
                "also run the calibration frames (every render-state class, four triangle shapes) and print the staged "
                "least-squares fit of the timing model's gateware terms (what timing_preset holds) and its error per frame");
  sub->add_flag("--fill", a->fill,
                "instead: the whole device's fill rate per scene class (a framebuffer-sized rectangle as two triangles, "
                "SPI slave to SPRAM / SDRAM co-simulated; the device's work clocks of the draw, SPI transfer time "
                "excluded) in px/clock and Mpixel/s at the profile's core clock")
      ->excludes(fit);
  sub->add_flag("--quick", a->quick, "two examples only (a smoke run); with --fill, 64 x 48 rectangles");
  sub->add_option("--config-dir", a->config_dir, "directory holding boards/");
  auto* save = sub->add_option("--save-rtl-counters", a->save_rtl,
                               "write the gateware's counters of every frame to FILE (JSON), for --rtl-counters");
  sub->add_option("--rtl-counters", a->load_rtl,
                  "take the gateware's counters from FILE (--save-rtl-counters of the same gateware and streams) "
                  "instead of co-simulating: seconds instead of minutes, for work on the timing model; stale once "
                  "the gateware changes")
      ->excludes(save)
      ->excludes("--fill");
  runners.emplace_back(sub, [&g, a] { return run_bench_rtl(g, *a); });
});

}  // namespace gpubridge::cli
