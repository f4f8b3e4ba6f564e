#pragma once
// `gpubridge bench accuracy`: throughput and error of every simulator accuracy configuration on the
// fixed scene set, with Mesa llvmpipe measured side by side as a peer (docs/accuracy-report.md).
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gpubridge/bench/cordic_front.hpp"
#include "gpubridge/bench/scenes.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/sim/options.hpp"

namespace gpubridge::bench {

struct AccuracyBenchOptions {
  bool quick = false;         // small scenes, 1 timed run: the smoke test of the test command
  unsigned scale = 1;         // divides the scene triangle counts (quick: 200)
  unsigned runs = 5;          // timed runs per measurement (best is reported), after 1 warm-up
  double min_seconds = 0.25;  // ... and more runs until this much time is spent (both sides; quick: 0)
  bool llvmpipe = true;       // measure the llvmpipe peer (omitted with a reason when unavailable)
  unsigned peer_rounds = 3;   // the peer and the minimal GL program alternate this often (best of all; quick: 1)
  std::vector<unsigned> threads{1, 2};
  std::vector<std::string> scenes;  // only these scenes (by name); empty = all
  bool exact_only = false;          // only the exact configuration (no other accuracy knobs)
  bool preview_only = false;        // only the exact and the preview configuration
  bool cordic = true;               // the CORDIC front of the torus example (cordic_front.hpp)
};

// Error of one renderer on one scene against the double-precision reference (the leading
// `error_subset` triangles, drawn with depth ALWAYS + write and no blending, so the last triangle
// covering a pixel owns it).
struct ErrorStats {
  std::uint64_t pixels = 0;              // reference-covered pixels judged
  std::uint64_t coverage_mismatches = 0; // pixels whose hit count or owning triangle differs
  double color_max = 0, color_mean = 0;     // 8-bit LSB (untextured scenes)
  double z_max = 0;                          // 24-bit LSB
  double texel_max = 0, texel_mean = 0;      // 1/256 texel of the 1024-texel probe (textured scenes)
  bool has_color = false, has_texel = false;
};

struct Row {
  std::string renderer;  // "sim" or "llvmpipe"
  std::string config;    // knob settings or llvmpipe's renderer string
  std::string scene;
  unsigned threads = 1;  // rasteriser threads (llvmpipe: 1 = LP_NUM_THREADS=0, 2 = two threads)
  double seconds = 0;    // best frame time
  double mtri_s = 0, mpix_s = 0;
  std::optional<double> ratio_vs_llvmpipe;  // sim throughput / llvmpipe throughput, same scene & threads
  // llvmpipe rows of the scenes bench/llvmpipe/minimal_gl.c draws: its best frame time in the same
  // run (same vertices, thread count, resolution), the peer's throughput as a fraction of its
  // throughput, and whether both frames had the same RGBA byte sum (the same picture).
  std::optional<double> minimal_gl_seconds, vs_minimal_gl;
  std::optional<bool> minimal_gl_same_image;
  std::optional<double> fill_fraction;  // mpix_s / the in-cache fill ceiling at the same thread count
  std::optional<ErrorStats> error;
};

// This machine's fill ceiling (issue 17): the pixel rate of the least work a depth-tested colour
// fill does per pixel, a 32-bit Z read-modify-write (LESS, every pixel passes) and a 32-bit colour
// write, 16 lanes (AVX-512 where the CPU has it), nothing else.
struct FillCeiling {
  unsigned threads = 1;
  std::string vectors;      // the instruction set the kernel ran with: "AVX-512", "AVX2" or "SSE2"
  double cache_mpix_s = 0;  // a 2,048-pixel tile per thread (16 KiB of Z + colour: L1): the physical limit
  double frame_mpix_s = 0;  // one 640x480 Z + colour split between the threads (2.4 MiB, the scenes' own)
  double dram_mpix_s = 0;   // 2 x 128 MiB split between the threads (beyond the last-level cache)
};

struct Report {
  std::string machine;      // CPU model, core count, load average at start
  std::string llvmpipe;     // renderer string, or why the llvmpipe rows are missing
  bool llvmpipe_ok = false;
  std::string minimal_gl;   // the minimal GL program run beside the peer, or why it did not run
  unsigned runs = 0;         // timed frames per measurement at least, after a warm-up ...
  double min_seconds = 0;    // ... and more until this much time had been spent (every side alike)
  std::vector<Scene> scenes;  // descriptions only (triangles cleared after the run)
  std::vector<std::uint64_t> scene_pixels;  // covered pixels per frame (exact simulator)
  std::vector<std::size_t> scene_triangles;  // triangles per frame
  std::vector<Row> rows;
  std::vector<FillCeiling> ceiling;  // per thread count, measured in the same run
  std::vector<std::string> goals;  // the speed goals with their measured ratios
  std::vector<std::string> preview_goals;  // preview vs exact per scene and thread count (issue 24)
  std::optional<CordicFront> cordic;  // its own section (cordic_front.hpp)
};

// "CPU model, N hardware threads, load average at start: a b c" (figures on a shared machine need it).
std::string machine_description();

// The simulator configurations measured: the exact default first.
std::vector<sim::AccuracyKnobs> bench_configs();

Result<Report> run_accuracy_bench(const AccuracyBenchOptions& options, const std::function<void(const std::string&)>& progress);

std::string report_markdown(const Report& r, const std::string& command);
nlohmann::json report_json(const Report& r);
std::string report_svg(const Report& r);

}  // namespace gpubridge::bench
