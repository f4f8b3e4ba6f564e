// gpubridge-demo: the example scenes. Renders them on the in-process simulator to PNG files, or
// streams them to a running gpubridged, or checks/regenerates their golden images, or shows how
// each fits each board profile and what frame rate it would reach there. Every example fits
// itself to the device it is given (fit.hpp); the choice is printed.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "demo_fit.hpp"
#include "gpubridge/common/image.hpp"
#include "gpubridge/common/json_text.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/draw/client_sink.hpp"
#include "gpubridge/draw/sim_sink.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/examples/golden.hpp"
#include "gpubridge/examples/cordic.hpp"
#include "gpubridge/examples/figures.hpp"

namespace {

using namespace gpubridge;
using namespace gpubridge::demo;
namespace fs = std::filesystem;

int run_list(bool json) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : examples::make_examples()) {
    const auto i = e->info();
    if (json)
      out.push_back({{"name", i.name}, {"seed", i.seed}, {"description", i.description}});
    else
      std::printf("%-16s %-18s %s\n", i.name.c_str(), i.seed.c_str(), i.description.c_str());
  }
  if (json) std::puts(json_text(out, 2).c_str());
  return 0;
}

int run_render(const std::vector<std::string>& names, const examples::ExampleParams& params,
               const FitOptions& fit_options, const std::string& board, const std::string& out_dir, unsigned first,
               unsigned frames, bool json) {
  auto list = select(names, params);
  if (!list) return fail(list.error().message);
  auto request = fit_options.request();
  if (!request) return fail(request.error().message, 2);
  auto device = board.empty() ? Result<examples::DeviceCaps>(examples::DeviceCaps{}) : board_device(board);
  if (!device) return fail(device.error().message, 2);
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) return fail(out_dir + ": cannot create the directory: " + ec.message());
  nlohmann::json written = nlohmann::json::array();
  for (auto& ex : *list) {
    const std::string name = ex->info().name;
    auto fitted = examples::configure(*ex, *device, *request);
    if (!fitted) return fail(fitted.error().message);
    if (!json) print_fit(name, *fitted);
    auto sink = draw::SimulatorSink::create(device->simulator_options());
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
      written.push_back({{"example", name}, {"frame", n}, {"path", path.string()}, {"crc", f->crc}, {"config", fit_json(*fitted)}});
      if (!json) std::printf("%s\n", path.string().c_str());
      return {};
    });
    if (!r) return fail(r.error().message);
  }
  if (json) std::puts(json_text(written, 2).c_str());
  return 0;
}

struct StreamOptions {
  std::string address, token;
  unsigned frames = 120;
  double fps = 30;
  unsigned window = 4;  // frames in flight (ContextOptions::frames_in_flight)
  bool sync = false;    // wait for every frame to execute (a round trip each)
};

int run_stream(const std::vector<std::string>& names, const examples::ExampleParams& params, const FitOptions& fit_options,
               const StreamOptions& o, bool json) {
  auto list = select(names, params);
  if (!list) return fail(list.error().message);
  auto request = fit_options.request();
  if (!request) return fail(request.error().message, 2);
  // An empty address or token: $GPUBRIDGE_ADDRESS / $GPUBRIDGE_TOKEN (client library).
  auto sink = draw::ClientSink::connect(o.address, "gpubridge-demo", o.token);
  if (!sink) return fail("cannot stream to the daemon: " + sink.error().message);
  const auto device = examples::DeviceCaps::from((*sink)->device());
  nlohmann::json summary = nlohmann::json::array();
  for (auto& ex : *list) {
    const std::string name = ex->info().name;
    auto fitted = examples::configure(*ex, device, *request);
    if (!fitted) return fail(fitted.error().message);
    if (!json) print_fit(name, *fitted);
    auto options = ex->options();
    options.frames_in_flight = o.sync ? 0 : o.window;
    auto ctx = draw::Context::create(**sink, options);
    if (!ctx) return fail(name + ": " + ctx.error().message);
    const unsigned frames = o.frames;
    const auto start = std::chrono::steady_clock::now();
    const std::uint64_t wire_before = (*sink)->client().wire_stats().bytes_sent;
    auto r = examples::run_frames(*ex, *ctx, 0, frames, [&](unsigned n) -> Result<void> {
      if (o.sync)
        if (auto f = ctx->flush(); !f) return f;
      if (o.fps > 0) std::this_thread::sleep_until(start + std::chrono::duration<double>((n + 1) / o.fps));
      return {};
    });
    if (!r) return fail(r.error().message);
    if (auto f = ctx->flush(); !f) return fail(name + ": " + f.error().message);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::uint64_t wire = (*sink)->client().wire_stats().bytes_sent - wire_before;
    summary.push_back({{"example", name}, {"frames", frames}, {"seconds", secs}, {"triangles", ctx->stats().emitted},
                       {"config", fit_json(*fitted)}, {"bytes_sent", wire},
                       {"compressed", (*sink)->client().session().compressed}});
    if (!json) std::printf("%-12s %u frames in %.2f s (%zu triangles sent)\n", name.c_str(), frames, secs, ctx->stats().emitted);
  }
  if (json) std::puts(json_text(summary, 2).c_str());
  return 0;
}

int run_goldens(const std::string& dir, const std::vector<std::string>& class_names, bool write, bool json) {
  std::vector<const examples::GoldenClass*> classes;
  for (const auto& n : class_names) {
    const auto* c = examples::find_golden_class(n);
    if (!c) {
      std::string known;
      for (const auto& k : examples::golden_classes()) known += " " + k.name;
      return fail("unknown class \"" + n + "\"; the classes are:" + known, 2);
    }
    classes.push_back(c);
  }
  if (classes.empty())
    for (const auto& c : examples::golden_classes()) classes.push_back(&c);
  nlohmann::json report = nlohmann::json::array();
  int failures = 0;
  for (const auto* cls : classes)
    for (auto& ex : examples::make_examples()) {
      const std::string name = ex->info().name;
      auto frames = examples::render_golden_frames(*ex, *cls);
      if (!frames) return fail(cls->name + ": " + frames.error().message);
      for (const auto& [frame, img] : *frames) {
        const fs::path path = examples::golden_path(dir, *cls, name, frame);
        if (write) {
          std::error_code ec;
          fs::create_directories(path.parent_path(), ec);
          if (auto s = save_png(path, img); !s) return fail(s.error().message);
          if (!json) std::printf("wrote %s\n", path.string().c_str());
          report.push_back({{"class", cls->name}, {"example", name}, {"frame", frame}, {"path", path.string()},
                            {"written", true}});
          continue;
        }
        auto golden = load_png(path);
        if (!golden)
          return fail(golden.error().message + " (create the goldens with: gpubridge-demo goldens --dir " + dir + " --write)");
        const auto diff = examples::compare_images(*golden, img);
        if (!diff.identical()) ++failures;
        // The first golden frame is named alone, later ones with their number.
        const std::string label = frame == examples::kGoldenFrame ? name : name + " frame " + std::to_string(frame);
        if (!json) std::printf("%-9s %-26s %s\n", cls->name.c_str(), label.c_str(), diff.summary().c_str());
        report.push_back({{"class", cls->name}, {"example", name}, {"frame", frame}, {"path", path.string()},
                          {"differing_pixels", diff.differing_pixels}, {"max_difference", diff.max_difference}});
      }
    }
  if (json) std::puts(json_text(report, 2).c_str());
  return failures ? 1 : 0;
}

// --size, --format, --no-depth, --without on a subcommand.
void add_fit_options(CLI::App* sub, FitOptions& o) {
  sub->add_option("--size", o.size, "force the framebuffer size, WIDTHxHEIGHT (default: the largest that fits)");
  sub->add_option("--format", o.format, "force the framebuffer format: RGBA8888, RGB565 or RGBA2222");
  sub->add_flag("--no-depth", o.no_depth, "draw without a depth buffer (each example's painter's order)");
  sub->add_option("--without", o.without, "do not use these device features: bilinear, blend, dither, rgb565, rgba2222, temporal, texture, depth (comma-separated)")
      ->delimiter(',')->allow_extra_args(false);
}

int run_figures(const std::string& dir, bool json) {
  auto figures = examples::write_figures(dir);
  if (!figures) return fail(figures.error().message);
  nlohmann::json report = nlohmann::json::array();
  for (const auto& f : *figures) {
    const std::string path = (fs::path(dir) / f.file).string();
    nlohmann::json j{{"path", path}, {"what", f.what}};
    if (f.has_error) j["mean_error_lsb"] = f.mean_error;
    report.push_back(j);
    if (json) continue;
    if (f.has_error)
      std::printf("%-44s %s (mean error %.2f LSB)\n", path.c_str(), f.what.c_str(), f.mean_error);
    else
      std::printf("%-44s %s\n", path.c_str(), f.what.c_str());
  }
  if (json) std::puts(json_text(report, 2).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"gpubridge-demo: the example scenes (one per seed), rendered on the simulator or streamed to gpubridged; "
               "each fits itself to the device it is given"};
  bool json = false;
  app.add_flag("--json", json, "machine-readable output");
  app.require_subcommand(1);

  auto* list = app.add_subcommand("list", "list the examples");

  std::vector<std::string> names;
  FitOptions fit_options;
  std::string out_dir = "demo-frames", board;
  unsigned frames = 1, first = examples::kGoldenFrame;
  auto* render = app.add_subcommand("render", "render examples on the in-process simulator and write PNG frames");
  render->add_option("EXAMPLES", names, "example names, or all (default)");
  render->add_option("--out", out_dir, "output directory (created)")->capture_default_str();
  render->add_option("--frames", frames, "frames per example")->check(CLI::Range(1u, 100000u))->capture_default_str();
  render->add_option("--first", first, "first frame number")->capture_default_str();
  render->add_option("--board", board, "render on a simulator with this board profile's device (configs/boards; default: the "
                                       "plain simulator)");
  add_fit_options(render, fit_options);

  examples::ExampleParams params;
  const std::string iterations_help = "shift-and-add steps per rotation of torus-cordic (" +
                                      std::to_string(examples::cordic::kMinIterations) + ".." +
                                      std::to_string(examples::cordic::kMaxIterations) + ")";
  render->add_option("--cordic-iterations", params.cordic_iterations, iterations_help)
      ->check(CLI::Range(examples::cordic::kMinIterations, examples::cordic::kMaxIterations))
      ->capture_default_str();

  StreamOptions so;
  auto* stream = app.add_subcommand("stream", "stream examples to a running gpubridged (the viewer shows them)");
  stream->add_option("EXAMPLES", names, "example names, or all (default)");
  stream->add_option("--connect", so.address,
                     "daemon address: unix:PATH, tcp:HOST:PORT or tls:HOST:PORT (default: $GPUBRIDGE_ADDRESS, else "
                     "the default socket)");
  stream->add_option("--token", so.token, "access token for a daemon that requires one (default: $GPUBRIDGE_TOKEN)");
  stream->add_option("--frames", so.frames, "frames per example")->check(CLI::Range(1u, 1000000u))->capture_default_str();
  stream->add_option("--fps", so.fps, "frames per second (0 = as fast as possible)")->check(CLI::Range(0.0, 1000.0))->capture_default_str();
  stream->add_option("--window", so.window, "frames in flight before a swap waits for the daemon (pipelined fences)")
      ->check(CLI::Range(1u, 1024u))
      ->capture_default_str();
  stream->add_flag("--sync", so.sync, "wait for every frame to execute before the next (a round trip each)");
  add_fit_options(stream, fit_options);
  stream->add_option("--cordic-iterations", params.cordic_iterations, iterations_help)
      ->check(CLI::Range(examples::cordic::kMinIterations, examples::cordic::kMaxIterations))
      ->capture_default_str();

  std::string golden_dir;
  std::vector<std::string> classes;
  bool write = false;
  auto* goldens = app.add_subcommand("goldens", "compare each example's golden frames with the committed PNGs, or rewrite them");
  goldens->add_option("--dir", golden_dir, "directory of the golden PNGs (examples/golden in the source tree)")->required();
  goldens->add_option("--class", classes, "device classes, comma-separated: large, up5k, up5k-min (default: all)")->delimiter(',')->allow_extra_args(false);
  goldens->add_flag("--write", write, "render and overwrite the goldens (when the renderer legitimately changed)");

  std::vector<std::string> boards;
  bool timing = false, markdown = false;
  auto* fit = app.add_subcommand("fit", "show the configuration each example picks on each board profile (--timing: the "
                                        "predicted frame rate there)");
  fit->add_option("EXAMPLES", names, "example names, or all (default)");
  fit->add_option("--board", boards, "board profiles (configs/boards, comma-separated; default: every one)")->delimiter(',')->allow_extra_args(false);
  fit->add_flag("--timing", timing, "predict each frame rate from the board's SPI and core clocks (docs/protocol.md section 19)");
  fit->add_flag("--markdown", markdown, "print Markdown tables (docs/examples.md)");
  add_fit_options(fit, fit_options);

  std::string figures_dir;
  auto* figures = app.add_subcommand(
      "figures", "render the temporal-dither and CORDIC figures of docs/examples.md (the torus held at its golden pose)");
  figures->add_option("--dir", figures_dir, "output directory (created; docs/screenshots in the source tree)")->required();

  for (auto* sub : {list, render, stream, goldens, fit, figures}) sub->add_flag("--json", json, "machine-readable output");
  CLI11_PARSE(app, argc, argv);
  gpubridge::init_logging("warn");
  if (*list) return run_list(json);
  if (*render) return run_render(names, params, fit_options, board, out_dir, first, frames, json);
  if (*stream) return run_stream(names, params, fit_options, so, json);
  if (*figures) return run_figures(figures_dir, json);
  if (*fit) return run_fit(names, boards, fit_options, timing, markdown, json);
  return run_goldens(golden_dir, classes, write, json);
}
