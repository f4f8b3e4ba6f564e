// `gpubridge bench accuracy`: speed against error of every simulator accuracy configuration, with
// Mesa llvmpipe measured side by side (bench/, docs/accuracy-report.md).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include <nlohmann/json.hpp>

#include "bench_group.hpp"
#include "command.hpp"
#ifdef GPUBRIDGE_HAVE_BENCH_LIB
#include "gpubridge/bench/accuracy_bench.hpp"
#include "gpubridge/common/json_text.hpp"
#endif

namespace gpubridge::cli {
namespace {

struct AccuracyArgs {
  bool quick = false;
  unsigned runs = 5;
  unsigned scale = 1;
  bool no_llvmpipe = false;
  std::string out_dir;
  std::vector<std::string> scenes;
  bool exact_only = false;
};

[[maybe_unused]] bool write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary);
  f << text;
  return bool(f);
}

#ifndef GPUBRIDGE_HAVE_BENCH_LIB
int run_accuracy(const GlobalOptions&, const AccuracyArgs&) {
  std::fprintf(stderr, "gpubridge bench accuracy: this build has no benchmarks (configure with -DGPUBRIDGE_BUILD_BENCH=ON)\n");
  return 1;
}
#else
int run_accuracy(const GlobalOptions& g, const AccuracyArgs& a) {
  bench::AccuracyBenchOptions opt;
  opt.quick = a.quick;
  opt.runs = a.runs;
  opt.scale = a.scale;
  opt.llvmpipe = !a.no_llvmpipe;
  opt.scenes = a.scenes;
  opt.exact_only = a.exact_only;
  if (!a.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(a.out_dir, ec);
    if (ec || !std::filesystem::is_directory(a.out_dir)) {
      std::fprintf(stderr, "gpubridge bench accuracy: cannot create output directory %s: %s\n", a.out_dir.c_str(),
                   ec.message().c_str());
      return 1;
    }
  }
  auto report = bench::run_accuracy_bench(opt, [](const std::string& step) { std::fprintf(stderr, "bench: %s\n", step.c_str()); });
  if (!report) {
    std::fprintf(stderr, "gpubridge bench accuracy: %s\n", report.error().message.c_str());
    return 1;
  }
  std::string command = "gpubridge bench accuracy";
  if (a.quick) command += " --quick";
  if (a.runs != 5) command += " --runs " + std::to_string(a.runs);
  if (a.scale != 1) command += " --scale " + std::to_string(a.scale);
  for (const auto& name : a.scenes) command += " --scene " + name;
  if (a.exact_only) command += " --exact-only";
  if (!a.out_dir.empty()) command += " --out-dir " + a.out_dir;
  const std::string md = bench::report_markdown(*report, command);
  const auto json = bench::report_json(*report);
  if (!a.out_dir.empty()) {
    const std::filesystem::path dir(a.out_dir);
    if (!write_file(dir / "accuracy-report.md", md) || !write_file(dir / "accuracy-report.json", json_text(json, 2) + "\n") ||
        !write_file(dir / "accuracy-front.svg", bench::report_svg(*report))) {
      std::fprintf(stderr, "gpubridge bench accuracy: cannot write the report files in %s\n", a.out_dir.c_str());
      return 1;
    }
  }
  if (g.json) std::puts(json_text(json, 2).c_str());
  else std::fputs(md.c_str(), stdout);
  if (!report->llvmpipe_ok) std::fprintf(stderr, "gpubridge bench accuracy: llvmpipe rows omitted: %s\n", report->llvmpipe.c_str());
  return 0;
}
#endif

}  // namespace

GPUBRIDGE_COMMAND("bench", 80, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  CLI::App* group = bench_group(app);
  auto* sub = group->add_subcommand(
      "accuracy",
      "throughput (Mtri/s, Mpix/s) and error against the double-precision reference of every simulator accuracy "
      "configuration at 1 and 2 threads, on a fixed scene set, with Mesa llvmpipe as a peer; prints Markdown "
      "(or JSON with --json) and writes accuracy-report.md/.json and accuracy-front.svg with --out-dir");
  auto args = std::make_shared<AccuracyArgs>();
  sub->add_flag("--quick", args->quick, "small scenes and one timed run (smoke test; figures are not meaningful)");
  sub->add_option("--runs", args->runs, "timed runs per measurement after one warm-up; the best is reported")
      ->check(CLI::Range(1u, 100u))
      ->capture_default_str();
  sub->add_option("--scale", args->scale, "divide the triangle counts of the scenes by this (1 = the full set)")
      ->check(CLI::Range(1u, 1000u))
      ->capture_default_str();
  sub->add_flag("--no-llvmpipe", args->no_llvmpipe, "skip the llvmpipe peer rows");
  sub->add_option("--scene", args->scenes,
                  "only this scene (repeatable): tri10-front, tri1k-front, tri50k-front, tri10-random, tri1k-random, "
                  "tri50k-random, road, cubes, fan, alpha-blend");
  sub->add_flag("--exact-only", args->exact_only, "only the exact configuration (skip the other accuracy knobs)");
  sub->add_option("--out-dir", args->out_dir, "directory for accuracy-report.md, accuracy-report.json, accuracy-front.svg");
  sub->fallthrough();
  runners.emplace_back(sub, [&g, args] { return run_accuracy(g, *args); });
});

}  // namespace gpubridge::cli
