// `gpubridge render INPUT --out frame.png`: runs a trace (text or binary) or a scene file through
// the in-process simulator and writes the last scanned-out frame (or FB_DRAW when nothing was
// swapped). Options expose the simulator's accuracy knobs, threads, the timing model and a dump of
// every covered pixel's interpolated attributes.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "command_input.hpp"
#include "device_option.hpp"
#include "render_dmc1.hpp"
#include "gpubridge/common/image.hpp"
#include "gpubridge/common/json_text.hpp"
#include "gpubridge/sim/device.hpp"
#include "gpubridge/sim/run_stream.hpp"
#include "gpubridge/sim/timing.hpp"

namespace gpubridge::cli {
namespace {

namespace fs = std::filesystem;
using protocol::PixelFormat;

struct RenderArgs {
  std::string input, out, dump_attributes, frames_dir;
  std::vector<std::string> accuracy, timing_params;
  unsigned threads = 1;
  bool timing = false;
  std::optional<std::uint64_t> vram_mib;  // spigpu only (default 8)
  protocol::DeviceKind device = protocol::DeviceKind::Spigpu;
  std::string textures, palette, raw, board, tty;  // DMC-1 only
};

struct FrameRecord {
  std::shared_ptr<const backends::ScanoutFrame> frame;
  sim::DeviceStats work;  // what the device did for this frame
};

int fail(const std::string& msg, int code = 1) {
  std::fprintf(stderr, "gpubridge render: %s\n", msg.c_str());
  return code;
}

nlohmann::json timing_json(const sim::TimingEstimate& e) {
  return {{"board_cycles", e.board_cycles}, {"pipeline_cycles", e.pipeline_cycles}, {"memory_cycles", e.memory_cycles},
          {"memory_bytes", e.memory_bytes}, {"board_ms", e.board_ms},               {"spi_ms", e.spi_ms},
          {"frame_ms", e.frame_ms},         {"fps", e.fps}};
}

int run_render(const GlobalOptions& g, const RenderArgs& a) {
  if (a.device == protocol::DeviceKind::Dmc1) {
    if (!a.accuracy.empty() || !a.dump_attributes.empty() || a.vram_mib)
      return fail("--accuracy, --dump-attributes and --vram-mib are spigpu options; the DMC-1 is always bit-exact", 2);
    return render_dmc1(g, Dmc1RenderArgs{a.input, a.out, a.raw, a.frames_dir, a.textures, a.palette, a.board, a.tty,
                                         a.timing_params, a.threads, a.timing});
  }
  if (!a.textures.empty() || !a.palette.empty() || !a.raw.empty() || !a.board.empty() || !a.tty.empty())
    return fail("--textures, --palette, --raw, --board and --tty are DMC-1 options; add --device dmc1", 2);
  if (a.out.empty() && a.frames_dir.empty() && !a.timing && a.dump_attributes.empty())
    return fail("nothing to produce; pass --out FILE.png (or --frames-dir, --timing, --dump-attributes)", 2);
  sim::DeviceOptions opt;
  auto knobs = sim::parse_knobs(a.accuracy);
  if (!knobs) return fail(knobs.error().message, 2);
  opt.accuracy = *knobs;
  opt.threads = a.threads;
  const std::uint64_t vram_mib = a.vram_mib.value_or(8);
  if (vram_mib < 1 || vram_mib > 4096) return fail("--vram-mib " + std::to_string(vram_mib) + ": expected 1..4096", 2);
  opt.vram_bytes = vram_mib << 20;
  opt.sdram_rows = a.timing;  // the timing model's row terms (section 19); a cost only --timing pays
  sim::BoardTiming board;
  for (const auto& s : a.timing_params)
    if (auto r = sim::apply_timing_setting(board, s); !r) return fail(r.error().message, 2);
  auto dev = sim::Device::create(opt);
  if (!dev) return fail(dev.error().message, 2);
  sim::Device& d = **dev;

  std::string kind;
  auto stream = load_commands(a.input, opt.vram_bytes, kind);
  if (!stream) return fail(stream.error().message);

  if (!a.frames_dir.empty()) {
    std::error_code ec;
    fs::create_directories(a.frames_dir, ec);
    if (ec) return fail("--frames-dir " + a.frames_dir + ": " + ec.message());
  }
  std::FILE* dump = nullptr;
  if (!a.dump_attributes.empty()) {
    dump = std::fopen(a.dump_attributes.c_str(), "w");
    if (!dump) return fail("--dump-attributes " + a.dump_attributes + ": cannot create the file");
    std::fputs("x,y,triangle,z,r,g,b,a,u,v\n", dump);
    d.set_pixel_observer([dump](const sim::CoveredPixel& p) {
      std::fprintf(dump, "%d,%d,%llu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", p.x, p.y,
                   static_cast<unsigned long long>(p.triangle), p.z, p.r, p.g, p.b, p.a, p.u, p.v);
    });
  }

  std::vector<FrameRecord> frames;
  std::string frame_error;
  sim::DeviceStats last_stats;
  d.set_scanout_callback([&](std::shared_ptr<const backends::ScanoutFrame> f) {
    const sim::DeviceStats now = d.stats();
    FrameRecord rec{f, sim::stats_difference(now, last_stats)};
    last_stats = now;
    if (!a.frames_dir.empty() && frame_error.empty()) {
      char name[32];
      std::snprintf(name, sizeof name, "frame-%05u.png", f->number);
      const Image img = image_from_device(f->format, f->width, f->height, f->pixels);
      if (auto r = save_png(fs::path(a.frames_dir) / name, img); !r) frame_error = r.error().message;
    }
    // Keep pixels only for the last frame (bounded memory for long traces).
    if (!frames.empty()) frames.back().frame = std::make_shared<backends::ScanoutFrame>(backends::ScanoutFrame{
                             frames.back().frame->number, frames.back().frame->width, frames.back().frame->height,
                             frames.back().frame->format, {}, frames.back().frame->crc, frames.back().frame->swap_time});
    frames.push_back(std::move(rec));
  });

  const auto t0 = std::chrono::steady_clock::now();
  auto ran = sim::run_stream(d, *stream);
  const double elapsed_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (dump) {
    d.set_pixel_observer(nullptr);
    const bool bad = std::ferror(dump) != 0;
    std::fclose(dump);
    if (bad) return fail("--dump-attributes " + a.dump_attributes + ": write failed (disk full?)");
  }
  if (!ran) return fail(a.input + ": " + ran.error().message);
  if (!frame_error.empty()) return fail(frame_error);

  // The image: last scanned-out frame, else the draw buffer.
  Image img;
  std::string source;
  std::uint32_t crc = 0;
  if (!frames.empty()) {
    const auto& f = *frames.back().frame;
    img = image_from_device(f.format, f.width, f.height, f.pixels);
    source = "scanout";
    crc = f.crc;
  } else {
    const std::uint64_t fmt = d.read_register(protocol::index_of(protocol::Reg::FB_FORMAT));
    const std::uint64_t base = d.read_register(protocol::index_of(protocol::Reg::FB_DRAW)) & 0xFFFFFFF0u;
    const auto pf = static_cast<PixelFormat>((fmt >> 32) & 3);
    const unsigned w = fmt & 0x7FF, h = (fmt >> 16) & 0x7FF;
    const std::uint64_t len = std::uint64_t{w} * h * protocol::bytes_per_pixel(pf);
    auto mem = d.memory();
    std::vector<std::uint8_t> bytes(len, 0);
    for (std::uint64_t i = 0; i < len && base + i < mem.size(); ++i) bytes[i] = mem[base + i];
    img = image_from_device(pf, w, h, bytes);
    source = "fb_draw";
  }
  if (!a.out.empty())
    if (auto r = save_png(a.out, img); !r) return fail(r.error().message);

  const sim::DeviceStats& st = d.stats();
  const std::uint16_t errors = d.errors();
  nlohmann::json timing = nlohmann::json::array();
  if (a.timing) {
    std::vector<FrameRecord> work = frames;
    const sim::DeviceStats tail = sim::stats_difference(st, last_stats);
    if (work.empty() || tail.triangles_kicked || tail.clear_bytes) work.push_back({nullptr, tail});
    for (const auto& rec : work) {
      const unsigned bpp = rec.frame ? protocol::bytes_per_pixel(rec.frame->format) : 4;
      const auto e = sim::estimate_timing(rec.work, board, bpp);
      auto j = timing_json(e);
      j["frame"] = rec.frame ? nlohmann::json(rec.frame->number) : nlohmann::json("unswapped");
      j["triangles"] = rec.work.triangles_rasterised;
      j["pixels"] = rec.work.pixels_depth_passed;
      timing.push_back(j);
    }
  }

  if (g.json) {
    nlohmann::json j{{"input", a.input},
                     {"kind", kind},
                     {"output", a.out},
                     {"image_source", source},
                     {"width", img.width},
                     {"height", img.height},
                     {"frames", frames.size()},
                     {"crc", crc},
                     {"triangles_kicked", st.triangles_kicked},
                     {"triangles_rasterised", st.triangles_rasterised},
                     {"pixels_written", st.pixels_depth_passed},
                     {"device_errors", protocol::describe_errors(errors)},
                     {"accuracy", sim::to_string(opt.accuracy)},
                     {"accuracy_mode", sim::accuracy_mode(opt.accuracy)},
                     {"threads", opt.threads},
                     {"elapsed_ms", elapsed_ms}};
    if (a.timing) j["timing"] = timing;
    std::puts(json_text(j, 2).c_str());
  } else {
    std::printf("rendered %s (%s): %zu frame(s) scanned out, %llu triangles, %llu pixels written in %.2f ms\n",
                a.input.c_str(), kind.c_str(), frames.size(), static_cast<unsigned long long>(st.triangles_kicked),
                static_cast<unsigned long long>(st.pixels_depth_passed), elapsed_ms);
    if (!a.out.empty())
      std::printf("wrote %s: %ux%u, %s\n", a.out.c_str(), img.width, img.height,
                  source == "scanout" ? "the last scanned-out frame" : "FB_DRAW (nothing was swapped)");
    if (opt.accuracy.preview)
      std::printf("accuracy: %s (the preview rasteriser: float planes, not the hardware's bits)\n",
                  sim::to_string(opt.accuracy).c_str());
    else if (!opt.accuracy.exact())
      std::printf("accuracy: knobs %s (not the exact hardware)\n", sim::to_string(opt.accuracy).c_str());
    else
      std::printf("accuracy: exact (the hardware, bit for bit)\n");
    for (const auto& t : timing)
      std::printf("timing frame %s: %.0f board cycles (pipeline %.0f, memory %.0f) = %.3f ms at %.1f MHz; SPI %.3f ms at "
                  "%.1f MHz; frame %.3f ms (%.1f fps)\n",
                  json_text(t["frame"]).c_str(), t["board_cycles"].get<double>(), t["pipeline_cycles"].get<double>(),
                  t["memory_cycles"].get<double>(), t["board_ms"].get<double>(), board.clock_mhz,
                  t["spi_ms"].get<double>(), board.spi_clock_mhz, t["frame_ms"].get<double>(), t["fps"].get<double>());
  }
  if (errors)
    std::fprintf(stderr, "gpubridge render: warning: the device raised error flags %s while running %s\n",
                 protocol::describe_errors(errors).c_str(), a.input.c_str());
  return 0;
}

}  // namespace

GPUBRIDGE_COMMAND("render", 10, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  auto* sub = app.add_subcommand(
      "render",
      "render a trace (text/binary) or a scene file (.json) in-process on the simulator and write a PNG; with --device "
      "dmc1, a DMC-1 command stream (.dmc1 or tinygpus .nfo) on the bit-exact DMC-1");
  auto a = std::make_shared<RenderArgs>();
  sub->add_option("INPUT", a->input, "trace (.trace/.txt text, .gbt binary) or scene (.json); DMC-1: stream (.dmc1, .nfo)")
      ->required();
  add_device_option(sub, a->device);
  sub->add_option("--textures", a->textures, "DMC-1: texture memory image (raw or .gz), mapped at 0x200000");
  sub->add_option("--palette", a->palette, "DMC-1: palette, 768 bytes of R6, G6, B6");
  sub->add_option("--raw", a->raw, "DMC-1: every frame as little-endian RGB565 words in the GPU's output order");
  sub->add_option("--out,-o", a->out, "PNG of the last scanned-out frame (FB_DRAW if nothing was swapped)");
  sub->add_option("--accuracy", a->accuracy,
                  "simulator accuracy: exact (default), preview (the float rasteriser: faster, not bit-exact; "
                  "docs/simulator.md) and/or knobs KNOB=VALUE: recip_bits=1..16 nr_steps=0..4 subpixel_bits=0..4 z_bits=1..24")
      ->expected(1, 16);
  sub->add_option("--threads", a->threads, "rasteriser threads (output is identical for any count)")
      ->check(CLI::Range(1u, 64u))
      ->capture_default_str();
  sub->add_flag("--timing", a->timing,
                "predict board time per frame with the timing model (docs/protocol.md section 19; DMC-1: docs/dmc1.md)");
  sub->add_option("--board-timing", a->timing_params,
                  "timing model settings KEY=VALUE (profile=up5k|ecp5|ecp5-50mhz, clock_mhz, spi_clock_mhz, "
                  "setup_cycles_CLASS, ...: docs/protocol.md section 19; DMC-1: clock_mhz, screen_cycles_per_word, ...)")
      ->expected(1, 32);
  sub->add_option("--dump-attributes", a->dump_attributes,
                  "CSV of every covered pixel: x,y,triangle,z,r,g,b,a,u,v (exact values, docs/simulator.md)");
  sub->add_option("--frames-dir", a->frames_dir, "write every scanned-out frame as DIR/frame-NNNNN.png");
  sub->add_option("--vram-mib", a->vram_mib, "simulated video memory in MiB (default 8)");
  sub->add_option("--board", a->board,
                  "DMC-1: also stream the commands to this board's SOC over its USB-UART (a DMC-1 board profile, e.g. "
                  "icebreaker-dmc1; `gpubridge boards`). The images written are the simulator's: the board sends none back");
  sub->add_option("--tty", a->tty, "DMC-1 with --board: the serial port (default: found from the profile's USB ids)");
  runners.emplace_back(sub, [&g, a] { return run_render(g, *a); });
});

}  // namespace gpubridge::cli
