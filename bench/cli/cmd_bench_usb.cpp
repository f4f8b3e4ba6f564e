// `gpubridge bench usb`: link efficiency of the board path on an emulated bridge (default: the
// FT232H profile at 30 MHz with BUSY wired). Figures come from the bytes and clocks the real
// driver produced, not from wall time, so they predict hardware independent of this machine.
#include <cstdio>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_group.hpp"
#include "command.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/usb/board_factory.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::cli {
namespace {

struct UsbBenchArgs {
  std::string board = "ft232h-generic", config_dir;
  unsigned writes = 30000;
  unsigned width = 640, height = 480;
  std::string format = "rgb565";
  double round_trip_us = 125;  // one high-speed microframe per USB round trip (assumption)
  bool hardware = false;
};

struct Delta {
  usb::BridgeStats before;
  const usb::BridgeStats& now;
  std::uint64_t spi_bits() const { return now.spi_bits - before.spi_bits; }
  std::uint64_t out() const { return now.usb_out_transfers - before.usb_out_transfers; }
  std::uint64_t in() const { return now.usb_in_transfers - before.usb_in_transfers; }
  std::uint64_t bytes_out() const { return now.usb_bytes_out - before.usb_bytes_out; }
  std::uint64_t round_trips() const { return now.round_trips - before.round_trips; }
  // SPI time plus the USB round trips the host had to wait for one after the other.
  double predicted_ms(double clock, double round_trip_us) const {
    return (static_cast<double>(spi_bits()) / clock + static_cast<double>(round_trips()) * round_trip_us * 1e-6) * 1e3;
  }
};

int run_usb_bench(const GlobalOptions& g, const UsbBenchArgs& a) {
  auto profile = usb::find_board_profile(a.config_dir.empty() ? usb::default_config_dir() : std::filesystem::path(a.config_dir), a.board);
  if (!profile) {
    std::fprintf(stderr, "gpubridge bench usb: %s\n", profile.error().message.c_str());
    return 1;
  }
  const auto fmt = protocol::parse_pixel_format(a.format);
  if (!fmt) {
    std::fprintf(stderr, "gpubridge bench usb: --format %s: expected rgba8888, rgb565 or rgba2222\n", a.format.c_str());
    return 2;
  }
  usb::BoardOpenOptions o;
  o.emulate = !a.hardware;
  auto board = usb::open_board(*profile, o);
  if (!board) {
    std::fprintf(stderr, "gpubridge bench usb: %s\n", board.error().message.c_str());
    return 1;
  }
  auto& b = **board;
  const double clock = b.bridge().clock_hz();

  // 1. A write-heavy frame: vertex attribute writes (queued, no side effects), then one flush.
  std::vector<std::uint8_t> frames;
  frames.reserve(std::size_t{a.writes} * protocol::kFrameBytes);
  for (unsigned i = 0; i < a.writes; ++i)
    protocol::append(frames, i % 2 ? protocol::write_frame(protocol::Reg::TEXCOORD, i) : protocol::write_frame(protocol::Reg::COLOR, i));
  Delta w{b.bridge().stats(), b.bridge().stats()};
  if (auto r = b.write_frames(protocol::FrameView{frames}); !r) {
    std::fprintf(stderr, "gpubridge bench usb: write: %s\n", r.error().message.c_str());
    return 1;
  }
  if (auto r = b.flush(); !r) {
    std::fprintf(stderr, "gpubridge bench usb: flush: %s\n", r.error().message.c_str());
    return 1;
  }
  const double payload_bits = 72.0 * a.writes;
  const double efficiency = payload_bits / static_cast<double>(w.spi_bits());
  const double write_ms = w.predicted_ms(clock, a.round_trip_us);

  // 2. Framebuffer readback, as scanout does it (single pass, FRAME_CRC checks it) and verified.
  const std::uint64_t fb_bytes = std::uint64_t{a.width} * a.height * protocol::bytes_per_pixel(*fmt);
  if (fb_bytes == 0 || fb_bytes > b.info().vram_bytes) {
    std::fprintf(stderr, "gpubridge bench usb: a %ux%u %s framebuffer does not fit the board's %llu bytes of video memory\n", a.width,
                 a.height, a.format.c_str(), static_cast<unsigned long long>(b.info().vram_bytes));
    return 2;
  }
  nlohmann::json readbacks = nlohmann::json::array();
  std::string text;
  // Streamed reads (FTDI's asynchronous IN queue) next to synchronous FIFO-sized rounds, same run.
  struct Variant {
    bool verify, stream;
  };
  std::vector<Variant> variants{{false, true}, {true, true}};
  if (profile->stream_reads && b.bridge().chip().starts_with("FT")) variants.insert(variants.begin() + 1, Variant{false, false});
  for (const Variant& v : variants) {
    usb::BoardOpenOptions ro = o;
    ro.board.verify_readback = v.verify;
    usb::BoardProfile rp = *profile;
    rp.stream_reads = v.stream && profile->stream_reads;
    auto rb_board = usb::open_board(rp, ro);
    if (!rb_board) {
      std::fprintf(stderr, "gpubridge bench usb: %s\n", rb_board.error().message.c_str());
      return 1;
    }
    Delta r{(*rb_board)->bridge().stats(), (*rb_board)->bridge().stats()};
    auto px = (*rb_board)->readback(0, static_cast<std::uint32_t>(fb_bytes));
    if (!px) {
      std::fprintf(stderr, "gpubridge bench usb: readback: %s\n", px.error().message.c_str());
      return 1;
    }
    const double ms = r.predicted_ms(clock, a.round_trip_us);
    readbacks.push_back({{"verified", v.verify}, {"streamed", rp.stream_reads}, {"bytes", fb_bytes}, {"spi_bits", r.spi_bits()},
                         {"usb_in_transfers", r.in()}, {"usb_out_transfers", r.out()}, {"round_trips", r.round_trips()},
                         {"predicted_ms", ms}});
    char line[320];
    std::snprintf(line, sizeof line,
                  "readback %ux%u %s (%llu B, %s, %s): %llu SPI bits, %llu IN + %llu OUT transfers, %llu round trips, predicted %.1f ms\n",
                  a.width, a.height, a.format.c_str(), static_cast<unsigned long long>(fb_bytes), v.verify ? "read twice" : "single pass",
                  rp.stream_reads ? "streamed" : "FIFO-sized rounds", static_cast<unsigned long long>(r.spi_bits()),
                  static_cast<unsigned long long>(r.in()), static_cast<unsigned long long>(r.out()),
                  static_cast<unsigned long long>(r.round_trips()), ms);
    text += line;
  }

  if (g.json) {
    nlohmann::json j{{"board", profile->name},
                     {"bridge", std::string(b.bridge().chip())},
                     {"emulated", !a.hardware},
                     {"spi_clock_hz", clock},
                     {"round_trip_us_assumed", a.round_trip_us},
                     {"write_frame",
                      {{"register_writes", a.writes},
                       {"payload_bits", payload_bits},
                       {"spi_bits", w.spi_bits()},
                       {"efficiency", efficiency},
                       {"usb_out_transfers", w.out()},
                       {"usb_in_transfers", w.in()},
                       {"round_trips", w.round_trips()},
                       {"usb_bytes_out", w.bytes_out()},
                       {"busy_waits", b.bridge().stats().busy_waits},
                       {"predicted_ms", write_ms}}},
                     {"readback", readbacks}};
    std::puts(json_text(j, 2).c_str());
    return 0;
  }
  std::printf("board %s, %s%s at %.3g MHz (round trip assumed %.0f us)\n", profile->name.c_str(), std::string(b.bridge().chip()).c_str(),
              a.hardware ? "" : " (emulated)", clock / 1e6, a.round_trip_us);
  std::printf("write-heavy frame: %u register writes, payload/SPI clock bits = %.1f%% (goal >= 95%%), %llu OUT + %llu IN transfers "
              "(%.2f per 1000 writes), %llu USB bytes out, predicted %.2f ms\n",
              a.writes, 100 * efficiency, static_cast<unsigned long long>(w.out()), static_cast<unsigned long long>(w.in()),
              1000.0 * static_cast<double>(w.out() + w.in()) / a.writes, static_cast<unsigned long long>(w.bytes_out()), write_ms);
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace

GPUBRIDGE_COMMAND("bench-usb", 81, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  CLI::App* group = bench_group(app);
  auto a = std::make_shared<UsbBenchArgs>();
  auto* sub = group->add_subcommand("usb",
                                    "board-path link efficiency on an emulated bridge (default FT232H at 30 MHz): payload bits per SPI "
                                    "clock bit for a write-heavy frame, USB transfers per frame, predicted framebuffer readback time");
  sub->add_option("--board", a->board, "board profile")->capture_default_str();
  sub->add_option("--config-dir", a->config_dir, "directory holding boards/ and cables/");
  sub->add_option("--writes", a->writes, "register writes in the write-heavy frame")->capture_default_str()->check(CLI::Range(1u, 10'000'000u));
  sub->add_option("--width", a->width, "readback framebuffer width")->capture_default_str()->check(CLI::Range(1u, 1024u));
  sub->add_option("--height", a->height, "readback framebuffer height")->capture_default_str()->check(CLI::Range(1u, 1024u));
  sub->add_option("--format", a->format, "readback pixel format (rgba8888, rgb565, rgba2222)")->capture_default_str();
  sub->add_option("--round-trip-us", a->round_trip_us, "assumed cost of one USB round trip in the prediction")->capture_default_str()
      ->check(CLI::Range(0.0, 100000.0));
  sub->add_flag("--hardware", a->hardware, "measure the real board instead of the emulated one");
  runners.emplace_back(sub, [&g, a] { return run_usb_bench(g, *a); });
});

}  // namespace gpubridge::cli
