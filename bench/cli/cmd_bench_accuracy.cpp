// `gpubridge bench accuracy`: speed against error of every simulator accuracy configuration, with
// Mesa llvmpipe measured side by side (bench/, docs/accuracy-report.md).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "bench_group.hpp"
#include "command.hpp"
#include "gpubridge/bench/accuracy_bench.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::cli {
namespace {

struct AccuracyArgs {
  bool quick = false;
  unsigned runs = 5;
  unsigned min_ms = 250;
  unsigned scale = 1;
  unsigned peer_rounds = 3;
  bool no_llvmpipe = false;
  std::string out_dir;
  std::vector<std::string> scenes;
  bool exact_only = false;
  bool preview_only = false;
  bool cordic_only = false;
};

bool write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary);
  f << text;
  return bool(f);
}

Result<std::string> read_file(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  if (!f) return make_error(p.string() + ": cannot read it");
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// Only the CORDIC front: printed, and with --out-dir spliced into the existing report there (its
// section of accuracy-report.md, its key of accuracy-report.json, cordic-front.svg), the rest of
// the report left as it was (regenerating that takes llvmpipe and a while).
int run_cordic_only(const GlobalOptions& g, const AccuracyArgs& a) {
  auto fail = [](const std::string& msg) {
    std::fprintf(stderr, "gpubridge bench accuracy --cordic-only: %s\n", msg.c_str());
    return 1;
  };
  std::filesystem::path md_path, json_path;
  std::string md;
  nlohmann::json report_json;
  if (!a.out_dir.empty()) {
    const std::filesystem::path dir(a.out_dir);
    md_path = dir / "accuracy-report.md";
    json_path = dir / "accuracy-report.json";
    auto text = read_file(md_path);
    auto jtext = read_file(json_path);
    if (!text || !jtext)
      return fail((text ? jtext.error() : text.error()).message + " (generate the whole report first: gpubridge bench accuracy --out-dir " +
                  a.out_dir + ")");
    md = std::move(text).value();
    report_json = nlohmann::json::parse(*jtext, nullptr, false);
    if (report_json.is_discarded() || !report_json.is_object())
      return fail(json_path.string() + ": not a JSON object (regenerate the whole report: gpubridge bench accuracy --out-dir " +
                  a.out_dir + ")");
  }
  bench::CordicFrontOptions opt;
  opt.quick = a.quick;
  opt.runs = 4 * a.runs;  // passes of milliseconds: four per run of the accuracy bench, as there
  auto front = bench::run_cordic_front(opt, [](const std::string& step) { std::fprintf(stderr, "bench: %s\n", step.c_str()); });
  if (!front) return fail(front.error().message);
  std::string command = "gpubridge bench accuracy --cordic-only";
  if (a.quick) command += " --quick";
  if (a.runs != 5) command += " --runs " + std::to_string(a.runs);
  if (!a.out_dir.empty()) command += " --out-dir " + a.out_dir;
  const std::string section = bench::cordic_front_markdown(*front, command);
  const auto json = bench::cordic_front_json(*front);
  if (!a.out_dir.empty()) {
    auto spliced = bench::splice_cordic_section(md, section);
    if (!spliced) return fail(md_path.string() + ": " + spliced.error().message);
    report_json["cordic_front"] = json;
    const std::filesystem::path dir(a.out_dir);
    if (!write_file(md_path, *spliced) || !write_file(json_path, json_text(report_json, 2) + "\n") ||
        !write_file(dir / "cordic-front.svg", bench::cordic_front_svg(*front)))
      return fail("cannot write the report files in " + a.out_dir);
  }
  if (g.json) std::puts(json_text(json, 2).c_str());
  else std::fputs(section.c_str(), stdout);
  return 0;
}

int run_accuracy(const GlobalOptions& g, const AccuracyArgs& a) {
  if (a.cordic_only) return run_cordic_only(g, a);
  bench::AccuracyBenchOptions opt;
  opt.quick = a.quick;
  opt.runs = a.runs;
  opt.min_seconds = a.min_ms * 1e-3;
  opt.scale = a.scale;
  opt.llvmpipe = !a.no_llvmpipe;
  opt.peer_rounds = a.peer_rounds;
  opt.scenes = a.scenes;
  opt.exact_only = a.exact_only;
  opt.preview_only = a.preview_only;
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
  if (a.min_ms != 250) command += " --min-ms " + std::to_string(a.min_ms);
  if (a.scale != 1) command += " --scale " + std::to_string(a.scale);
  if (a.peer_rounds != 3) command += " --peer-rounds " + std::to_string(a.peer_rounds);
  for (const auto& name : a.scenes) command += " --scene " + name;
  if (a.exact_only) command += " --exact-only";
  if (a.preview_only) command += " --preview-only";
  if (!a.out_dir.empty()) command += " --out-dir " + a.out_dir;
  const std::string md = bench::report_markdown(*report, command);
  const auto json = bench::report_json(*report);
  if (!a.out_dir.empty()) {
    const std::filesystem::path dir(a.out_dir);
    if (!write_file(dir / "accuracy-report.md", md) || !write_file(dir / "accuracy-report.json", json_text(json, 2) + "\n") ||
        !write_file(dir / "accuracy-front.svg", bench::report_svg(*report)) ||
        (report->cordic && !write_file(dir / "cordic-front.svg", bench::cordic_front_svg(*report->cordic)))) {
      std::fprintf(stderr, "gpubridge bench accuracy: cannot write the report files in %s\n", a.out_dir.c_str());
      return 1;
    }
  }
  if (g.json) std::puts(json_text(json, 2).c_str());
  else std::fputs(md.c_str(), stdout);
  if (!report->llvmpipe_ok) std::fprintf(stderr, "gpubridge bench accuracy: llvmpipe rows omitted: %s\n", report->llvmpipe.c_str());
  return 0;
}

}  // namespace

GPUBRIDGE_COMMAND("bench", 80, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  CLI::App* group = bench_group(app);
  auto* sub = group->add_subcommand(
      "accuracy",
      "throughput (Mtri/s, Mpix/s) and error against the double-precision reference of every simulator accuracy "
      "configuration at 1 and 2 threads, on a fixed scene set, with Mesa llvmpipe as a peer; prints Markdown "
      "(or JSON with --json) and writes accuracy-report.md/.json, accuracy-front.svg and cordic-front.svg with "
      "--out-dir; the report ends with the CORDIC front of the torus example");
  auto args = std::make_shared<AccuracyArgs>();
  sub->add_flag("--quick", args->quick, "small scenes and one timed run (smoke test; figures are not meaningful)");
  sub->add_option("--runs", args->runs, "timed runs per measurement after one warm-up; the best is reported")
      ->check(CLI::Range(1u, 100u))
      ->capture_default_str();
  sub->add_option("--min-ms", args->min_ms,
                  "and more timed runs until this many milliseconds of frames have passed (the simulator, the "
                  "llvmpipe peer and the minimal GL program alike; 0 = --runs only; --quick: 0)")
      ->check(CLI::Range(0u, 60000u))
      ->capture_default_str();
  sub->add_option("--scale", args->scale, "divide the triangle counts of the scenes by this (1 = the full set)")
      ->check(CLI::Range(1u, 1000u))
      ->capture_default_str();
  sub->add_flag("--no-llvmpipe", args->no_llvmpipe, "skip the llvmpipe peer rows");
  sub->add_option("--peer-rounds", args->peer_rounds,
                  "rounds in which the llvmpipe peer and the minimal GL program (bench/llvmpipe/minimal_gl.c) "
                  "alternate, per thread count; each keeps its best frame; the simulator's exact configuration is timed in as "
                  "many rounds (--quick: 1)")
      ->check(CLI::Range(1u, 20u))
      ->capture_default_str();
  sub->add_option("--scene", args->scenes,
                  "only this scene (repeatable): tri10-front, tri1k-front, tri50k-front, tri10-random, tri1k-random, "
                  "tri50k-random, road, cubes, fan, alpha-blend");
  sub->add_flag("--exact-only", args->exact_only, "only the exact configuration (skip the other accuracy knobs)");
  sub->add_flag("--preview-only", args->preview_only,
                "only the exact and the preview configuration (the preview-vs-exact goal lines)")
      ->excludes("--exact-only");
  sub->add_flag("--cordic-only", args->cordic_only,
                "only the CORDIC front (the torus example's shift-and-add vertex stage, 4..16 iterations, against "
                "floating point); with --out-dir, replaces that section of the existing accuracy-report.md/.json "
                "and writes cordic-front.svg, leaving the rest of the report as it was");
  sub->add_option("--out-dir", args->out_dir, "directory for accuracy-report.md, accuracy-report.json, accuracy-front.svg");
  runners.emplace_back(sub, [&g, args] { return run_accuracy(g, *args); });
});

}  // namespace gpubridge::cli
