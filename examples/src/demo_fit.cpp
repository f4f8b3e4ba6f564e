#include "demo_fit.hpp"

#include <cstdio>
#include <map>

#include <fmt/format.h>

#include "gpubridge/common/json_text.hpp"
#include "gpubridge/examples/prediction.hpp"
#include "gpubridge/rtl/gateware_profile.hpp"
#include "gpubridge/usb/board_profile.hpp"

namespace gpubridge::demo {
namespace {

examples::DeviceCaps device_of(const usb::BoardProfile& p) {
  examples::DeviceCaps d;
  d.name = p.name;
  d.vram_bytes = std::uint64_t{p.vram_kib} * 1024;
  d.max_width = p.max_width;
  d.max_height = p.max_height;
  // A board that names its gateware profile has exactly that profile's CAPS.FEATURES and CAPS2 (the
  // iCEBreaker's up5k: no texturing, bilinear, blending or depth buffer); the generic profiles stand
  // for any design and keep every feature.
  if (const auto g = rtl::parse_gateware_profile(p.gateware)) {
    const auto caps = rtl::caps_of(*g);
    d.features = static_cast<std::uint16_t>(caps.features | ((caps.features2 & sim::FEATURE2_DEPTH) ? examples::kDepthBuffer : 0));
  }
  return d;
}

examples::BoardLink link_of(const usb::BoardProfile& p) {
  return {p.name, p.clock_mhz, p.spi_clock_hz / 1e6, p.scanout == usb::ScanoutMode::Readback};
}

Result<std::vector<usb::BoardProfile>> chosen_boards(const std::vector<std::string>& names) {
  auto all = usb::load_board_profiles(usb::default_config_dir());
  if (!all || names.empty()) return all;
  std::vector<usb::BoardProfile> out;
  for (const auto& n : names) {
    auto p = usb::find_board_profile(usb::default_config_dir(), n);
    if (!p) return p.error();
    out.push_back(std::move(*p));
  }
  return out;
}

nlohmann::json prediction_json(const examples::FramePrediction& p) {
  return {{"spi_frames", p.work.frames_received},
          {"triangles", p.work.triangles_rasterised},
          {"pixels", p.work.pixels_depth_passed},
          {"pipeline_cycles", p.estimate.pipeline_cycles},
          {"memory_bytes", p.estimate.memory_bytes},
          {"board_cycles", p.estimate.board_cycles},
          {"board_ms", p.estimate.board_ms},
          {"spi_ms", p.estimate.spi_ms},
          {"readback_ms", p.readback_ms},
          {"fps", p.fps},
          {"fps_with_readback", p.fps_with_readback}};
}

std::string fps_text(double fps) { return fps >= 100 ? fmt::format("{:.0f}", fps) : fmt::format("{:.1f}", fps); }

}  // namespace

int fail(const std::string& msg, int code) {
  std::fprintf(stderr, "gpubridge-demo: %s\n", msg.c_str());
  return code;
}

Result<std::vector<std::unique_ptr<examples::Example>>> select(const std::vector<std::string>& names,
                                                               const examples::ExampleParams& params) {
  std::vector<std::unique_ptr<examples::Example>> out;
  if (names.empty() || (names.size() == 1 && names[0] == "all")) return examples::make_examples(params);
  for (const auto& n : names) {
    auto e = examples::make_example(n, params);
    if (!e) {
      std::string list;
      for (const auto& k : examples::example_names()) list += " " + k;
      return make_error("unknown example \"" + n + "\"; the examples are:" + list + " (or all)");
    }
    out.push_back(std::move(e));
  }
  return out;
}

Result<examples::FitRequest> FitOptions::request() const {
  examples::FitRequest r;
  if (!size.empty()) {
    auto s = examples::parse_size(size);
    if (!s) return make_error("--size " + s.error().message);
    r.size = *s;
  }
  if (!format.empty()) {
    const auto f = protocol::parse_pixel_format(format);
    if (!f) return make_error("--format \"" + format + "\": expected RGBA8888, RGB565 or RGBA2222");
    r.format = *f;
  }
  r.no_depth = no_depth;
  for (const auto& w : without) {
    const auto bit = examples::parse_feature(w);
    if (!bit)
      return make_error("--without \"" + w + "\": expected " +
                        examples::feature_names(0xFFFF) + " (comma-separated)");
    r.without |= *bit;
  }
  return r;
}

Result<examples::DeviceCaps> board_device(const std::string& name) {
  auto p = usb::find_board_profile(usb::default_config_dir(), name);
  if (!p) return p.error();
  return device_of(*p);
}

nlohmann::json fit_json(const examples::Fit& f) {
  nlohmann::json textures = nlohmann::json::array();
  for (const auto& t : f.textures)
    textures.push_back({{"name", t.name},
                        {"width", t.width},
                        {"height", t.height},
                        {"format", protocol::to_string(t.format)},
                        {"bilinear", t.bilinear}});
  return {{"device", {{"name", f.device.name},
                      {"vram_bytes", f.device.vram_bytes},
                      {"max_width", f.device.max_width},
                      {"max_height", f.device.max_height},
                      {"features", examples::feature_names(f.device.features)}}},
          {"width", f.context.width},
          {"height", f.context.height},
          {"format", protocol::to_string(f.context.format)},
          {"dither", f.dither},
          {"double_buffer", f.context.double_buffer},
          {"depth_buffer", f.context.depth_buffer},
          {"features_used", examples::feature_names(f.features)},
          {"textures", textures},
          {"vram_bytes", f.vram_bytes},
          {"gave_up", f.gave_up},
          {"summary", f.summary()}};
}

void print_fit(const std::string& example, const examples::Fit& f) {
  std::printf("%s on %s: %s\n", example.c_str(), f.device.name.c_str(), f.summary().c_str());
  for (const auto& g : f.gave_up) std::printf("  gave up: %s\n", g.c_str());
}

int run_fit(const std::vector<std::string>& names, const std::vector<std::string>& board_names, const FitOptions& options,
            bool timing, bool markdown, bool json) {
  auto request = options.request();
  if (!request) return fail(request.error().message, 2);
  auto boards = chosen_boards(board_names);
  if (!boards) return fail(boards.error().message, 2);
  auto list = select(names);
  if (!list) return fail(list.error().message);

  nlohmann::json out = nlohmann::json::array();
  // Markdown: the configurations (boards sharing one are listed together), then the frame rates.
  std::vector<std::string> example_order;
  std::map<std::string, std::vector<std::pair<std::string, std::vector<std::string>>>> configs;  // example → (summary, boards)
  std::map<std::string, std::map<std::string, std::string>> rates;                               // example → board → cell
  for (const auto& board : *boards) {
    const auto device = device_of(board);
    if (!json && !markdown)
      std::printf("%s (%s; %u KiB, %ux%u at most; %s SPI at %g MHz, core %g MHz)\n", board.name.c_str(), board.fpga.c_str(),
                  board.vram_kib, board.max_width, board.max_height, std::string(usb::to_string(board.chip)).c_str(),
                  board.spi_clock_hz / 1e6, board.clock_mhz);
    for (auto& ex : *list) {
      const std::string name = ex->info().name;
      nlohmann::json entry{{"board", board.name}, {"example", name}};
      examples::Fit fitted;
      std::optional<examples::FramePrediction> prediction;
      if (timing) {
        auto p = examples::predict_frame(*ex, device, link_of(board), *request);
        if (!p) return fail(board.name + ": " + p.error().message);
        fitted = p->fit;
        prediction = *p;
        entry["timing"] = prediction_json(*p);
      } else {
        auto f = examples::configure(*ex, device, *request);
        if (!f) return fail(board.name + ": " + f.error().message);
        fitted = *f;
      }
      entry["config"] = fit_json(fitted);
      out.push_back(entry);
      if (json) continue;
      if (markdown) {
        if (configs.find(name) == configs.end()) example_order.push_back(name);
        auto& rows = configs[name];
        std::string text = fitted.choice() + "; " + fmt::format("{:.0f} KiB", fitted.vram_bytes / 1024.0);
        for (const auto& g : fitted.gave_up) text += "<br>gave up: " + g;
        auto it = std::find_if(rows.begin(), rows.end(), [&](const auto& r) { return r.first == text; });
        if (it == rows.end()) rows.push_back({text, {board.name}});
        else it->second.push_back(board.name);
        if (prediction)
          rates[name][board.name] = fps_text(prediction->fps) + (link_of(board).readback ? " (" + fps_text(prediction->fps_with_readback) + ")" : "");
        continue;
      }
      std::printf("  %-12s %s\n", name.c_str(), fitted.summary().c_str());
      for (const auto& g : fitted.gave_up) std::printf("  %-12s gave up: %s\n", "", g.c_str());
      if (prediction)
        std::printf("  %-12s %llu SPI frames, board %.2f ms at %g MHz, SPI %.2f ms at %g MHz: %s fps%s\n", "",
                    static_cast<unsigned long long>(prediction->work.frames_received), prediction->estimate.board_ms,
                    board.clock_mhz, prediction->estimate.spi_ms, board.spi_clock_hz / 1e6, fps_text(prediction->fps).c_str(),
                    link_of(board).readback
                        ? fmt::format(" ({} fps with the daemon's readback for its viewers, {:.2f} ms)",
                                      fps_text(prediction->fps_with_readback), prediction->readback_ms)
                              .c_str()
                        : "");
    }
  }
  if (json) {
    std::puts(json_text(out, 2).c_str());
    return 0;
  }
  if (!markdown) return 0;
  std::printf("| example | configuration | boards |\n|---|---|---|\n");
  for (const auto& name : example_order)
    for (const auto& [text, on] : configs[name]) {
      std::string board_list;
      for (const auto& b : on) board_list += (board_list.empty() ? "" : ", ") + b;
      std::printf("| %s | %s | %s |\n", name.c_str(), text.c_str(), board_list.c_str());
    }
  if (!timing) return 0;
  std::printf("\n| example |");
  for (const auto& b : *boards) std::printf(" %s |", b.name.c_str());
  std::printf("\n|---|");
  for (std::size_t i = 0; i < boards->size(); ++i) std::printf("---|");
  std::printf("\n");
  for (const auto& name : example_order) {
    std::printf("| %s |", name.c_str());
    for (const auto& b : *boards) std::printf(" %s |", rates[name][b.name].c_str());
    std::printf("\n");
  }
  return 0;
}

}  // namespace gpubridge::demo
