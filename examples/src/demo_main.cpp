// gpubridge-demo: the example scenes. Renders them on the in-process simulator to PNG files, or
// streams them to a running gpubridged, or checks/regenerates their golden images.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/draw/sim_sink.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/examples/golden.hpp"
#if GPUBRIDGE_DRAW_HAS_CLIENT
#include "gpubridge/draw/client_sink.hpp"
#include "gpubridge/common/json_text.hpp"
#endif

namespace {

using namespace gpubridge;
namespace fs = std::filesystem;

int fail(const std::string& msg) {
  std::fprintf(stderr, "gpubridge-demo: %s\n", msg.c_str());
  return 1;
}

Result<std::vector<std::unique_ptr<examples::Example>>> select(const std::vector<std::string>& names) {
  std::vector<std::unique_ptr<examples::Example>> out;
  if (names.empty() || (names.size() == 1 && names[0] == "all")) return examples::make_examples();
  for (const auto& n : names) {
    auto e = examples::make_example(n);
    if (!e) {
      std::string list;
      for (const auto& k : examples::example_names()) list += " " + k;
      return make_error("unknown example \"" + n + "\"; the examples are:" + list + " (or all)");
    }
    out.push_back(std::move(e));
  }
  return out;
}

int run_list(bool json) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : examples::make_examples()) {
    const auto i = e->info();
    if (json)
      out.push_back({{"name", i.name}, {"seed", i.seed}, {"description", i.description}});
    else
      std::printf("%-12s %-18s %s\n", i.name.c_str(), i.seed.c_str(), i.description.c_str());
  }
  if (json) std::puts(json_text(out, 2).c_str());
  return 0;
}

int run_render(const std::vector<std::string>& names, const std::string& out_dir, unsigned first, unsigned frames,
               bool json) {
  auto list = select(names);
  if (!list) return fail(list.error().message);
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) return fail(out_dir + ": cannot create the directory: " + ec.message());
  nlohmann::json written = nlohmann::json::array();
  for (auto& ex : *list) {
    const std::string name = ex->info().name;
    auto sink = draw::SimulatorSink::create();
    if (!sink) return fail(sink.error().message);
    auto ctx = draw::Context::create(**sink, ex->options());
    if (!ctx) return fail(name + ": " + ctx.error().message);
    auto r = examples::run_frames(*ex, *ctx, first, frames, [&](unsigned n) -> Result<void> {
      const auto f = (*sink)->latest_frame();
      if (!f) return make_error(name + ": the swap produced no frame");
      char file[64];
      std::snprintf(file, sizeof file, "%s-%04u.png", name.c_str(), n);
      const fs::path path = fs::path(out_dir) / file;
      if (auto s = save_png(path, image_from_device(f->format, f->width, f->height, f->pixels)); !s) return s;
      written.push_back({{"example", name}, {"frame", n}, {"path", path.string()}, {"crc", f->crc}});
      if (!json) std::printf("%s\n", path.string().c_str());
      return {};
    });
    if (!r) return fail(r.error().message);
  }
  if (json) std::puts(json_text(written, 2).c_str());
  return 0;
}

int run_stream(const std::vector<std::string>& names, const std::string& address, unsigned frames, double fps,
               bool json) {
#if GPUBRIDGE_DRAW_HAS_CLIENT
  auto list = select(names);
  if (!list) return fail(list.error().message);
  auto sink = draw::ClientSink::connect(address, "gpubridge-demo");
  if (!sink) return fail("cannot stream to the daemon: " + sink.error().message);
  nlohmann::json summary = nlohmann::json::array();
  for (auto& ex : *list) {
    const std::string name = ex->info().name;
    auto ctx = draw::Context::create(**sink, ex->options());
    if (!ctx) return fail(name + ": " + ctx.error().message);
    const auto start = std::chrono::steady_clock::now();
    auto r = examples::run_frames(*ex, *ctx, 0, frames, [&](unsigned n) -> Result<void> {
      if (fps > 0) std::this_thread::sleep_until(start + std::chrono::duration<double>((n + 1) / fps));
      return {};
    });
    if (!r) return fail(r.error().message);
    if (auto f = ctx->flush(); !f) return fail(name + ": " + f.error().message);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    summary.push_back({{"example", name}, {"frames", frames}, {"seconds", secs}, {"triangles", ctx->stats().emitted}});
    if (!json) std::printf("%-12s %u frames in %.2f s (%zu triangles sent)\n", name.c_str(), frames, secs, ctx->stats().emitted);
  }
  if (json) std::puts(json_text(summary, 2).c_str());
  return 0;
#else
  (void)names, (void)address, (void)frames, (void)fps, (void)json;
  return fail("this build has no daemon client library (gpubridge_client); use `render`");
#endif
}

int run_goldens(const std::string& dir, bool write, bool json) {
  nlohmann::json report = nlohmann::json::array();
  int failures = 0;
  for (auto& ex : examples::make_examples()) {
    const std::string name = ex->info().name;
    auto img = examples::render_golden_frame(*ex);
    if (!img) return fail(img.error().message);
    const fs::path path = examples::golden_path(dir, name);
    if (write) {
      if (auto s = save_png(path, *img); !s) return fail(s.error().message);
      if (!json) std::printf("wrote %s\n", path.string().c_str());
      report.push_back({{"example", name}, {"path", path.string()}, {"written", true}});
      continue;
    }
    auto golden = load_png(path);
    if (!golden) return fail(golden.error().message + " (create the goldens with: gpubridge-demo goldens --write " + dir + ")");
    const auto diff = examples::compare_images(*golden, *img);
    if (!diff.identical()) ++failures;
    if (!json) std::printf("%-12s %s\n", name.c_str(), diff.summary().c_str());
    report.push_back({{"example", name}, {"path", path.string()}, {"differing_pixels", diff.differing_pixels},
                      {"max_difference", diff.max_difference}});
  }
  if (json) std::puts(json_text(report, 2).c_str());
  return failures ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"gpubridge-demo: the example scenes (one per seed), rendered on the simulator or streamed to gpubridged"};
  bool json = false;
  app.add_flag("--json", json, "machine-readable output");
  app.require_subcommand(1);

  auto* list = app.add_subcommand("list", "list the examples");

  std::vector<std::string> names;
  std::string out_dir = "demo-frames";
  unsigned frames = 1, first = examples::kGoldenFrame;
  auto* render = app.add_subcommand("render", "render examples on the in-process simulator and write PNG frames");
  render->add_option("EXAMPLES", names, "example names, or all (default)");
  render->add_option("--out", out_dir, "output directory (created)")->capture_default_str();
  render->add_option("--frames", frames, "frames per example")->check(CLI::Range(1u, 100000u))->capture_default_str();
  render->add_option("--first", first, "first frame number")->capture_default_str();

  std::string address;
  unsigned stream_frames = 120;
  double fps = 30;
  auto* stream = app.add_subcommand("stream", "stream examples to a running gpubridged (the viewer shows them)");
  stream->add_option("EXAMPLES", names, "example names, or all (default)");
  stream->add_option("--connect", address, "daemon address: unix:PATH or tcp:HOST:PORT (default: the default socket)");
  stream->add_option("--frames", stream_frames, "frames per example")->check(CLI::Range(1u, 1000000u))->capture_default_str();
  stream->add_option("--fps", fps, "frames per second (0 = as fast as possible)")->check(CLI::Range(0.0, 1000.0))->capture_default_str();

  std::string golden_dir;
  bool write = false;
  auto* goldens = app.add_subcommand("goldens", "compare each example's golden frame with its committed PNG, or rewrite them");
  goldens->add_option("--dir", golden_dir, "directory of the golden PNGs (examples/golden in the source tree)")->required();
  goldens->add_flag("--write", write, "render and overwrite the goldens (when the renderer legitimately changed)");

  for (auto* sub : {list, render, stream, goldens}) sub->add_flag("--json", json, "machine-readable output");
  CLI11_PARSE(app, argc, argv);
  gpubridge::init_logging("warn");
  if (*list) return run_list(json);
  if (*render) return run_render(names, out_dir, first, frames, json);
  if (*stream) return run_stream(names, address, stream_frames, fps, json);
  return run_goldens(golden_dir, write, json);
}
