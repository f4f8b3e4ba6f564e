// `gpubridge render --device dmc1 STREAM --textures FILE --palette FILE --out frame.png [--raw out.rgb565]
// [--frames-dir DIR] [--timing] [--board NAME [--tty PATH]] [--json]`: runs a DMC-1 stream on the
// in-process DMC-1 and writes its frames (the RTL's, bit for bit; docs/dmc1.md); with --board it also
// streams the commands to that board's standalone SOC over its USB-UART.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/json_text.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/dmc1/link.hpp"
#include "gpubridge/dmc1/serial_link.hpp"
#include "gpubridge/dmc1/stream.hpp"
#include "gpubridge/dmc1/uart.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/usb_tty.hpp"
#include "render_dmc1.hpp"

namespace gpubridge::cli {
namespace {

namespace fs = std::filesystem;

int fail(const std::string& msg, int code = 1) {
  std::fprintf(stderr, "gpubridge render: %s\n", msg.c_str());
  return code;
}

// --raw: every frame appended to the file as it completes, as little-endian RGB565 words (the golden
// format). Written frame by frame: a long stream's frames never accumulate in memory.
class RawWriter {
 public:
  Result<void> open(const std::string& path) {
    path_ = path;
    file_.open(path, std::ios::binary | std::ios::trunc);
    if (!file_) return make_error(path + ": cannot create the file (check the directory exists and is writable)");
    return {};
  }
  bool is_open() const { return file_.is_open(); }
  void append(std::span<const std::uint16_t> words) {
    bytes_.resize(words.size() * 2);
    for (std::size_t i = 0; i < words.size(); ++i) {
      bytes_[2 * i] = static_cast<char>(words[i] & 0xFF);
      bytes_[2 * i + 1] = static_cast<char>(words[i] >> 8);
    }
    file_.write(bytes_.data(), static_cast<std::streamsize>(bytes_.size()));
    written_ += bytes_.size();
  }
  Result<void> close() {
    file_.close();
    if (!file_) return make_error(path_ + ": write failed (disk full?)");
    return {};
  }
  std::uint64_t written() const { return written_; }

 private:
  std::string path_;
  std::ofstream file_;
  std::vector<char> bytes_;  // one frame, reused
  std::uint64_t written_ = 0;
};

std::atomic<bool> g_send_interrupted{false};  // executable-level: SIGINT while streaming to a board

// --board: the stream to the board's SOC over its USB-UART, after checking that the SOC's command
// FIFO keeps up at the profile's rate (nothing flow-controls it; overflowing commands are lost).
struct BoardSend {
  std::string board, tty;
  unsigned baud = 0;
  dmc1::SerialStats sent;
  double seconds = 0;
  unsigned max_fifo = 0;
};

Result<BoardSend> send_to_board(const Dmc1RenderArgs& a, std::span<const std::uint64_t> words,
                                std::shared_ptr<const dmc1::TextureMemory> textures, const dmc1::TimingParameters& timing) {
  auto profile = usb::find_uart_board_profile(usb::default_config_dir(), a.board);
  if (!profile) return profile.error();
  if (profile->device_kind != protocol::DeviceKind::Dmc1)
    return make_error("--board " + a.board + ": a " + std::string(protocol::device_kind_info(profile->device_kind).label) +
                      " board, not a DMC-1");
  BoardSend out;
  out.board = profile->name;
  out.baud = profile->baud;
  auto link = dmc1::estimate_link(words, profile->baud, textures, timing);
  if (!link) return link.error();
  out.max_fifo = link->max_fifo;
  if (link->overflow) {
    auto lossless = dmc1::fastest_lossless_baud(words, textures, timing);
    return make_error("at " + std::to_string(profile->baud) + " baud this stream would queue " + std::to_string(link->max_fifo) +
                      " commands in the SOC's " + std::to_string(dmc1::kStandaloneFifoDepth) +
                      "-entry FIFO, which nothing flow-controls: the board would lose commands. Use a rate up to " +
                      (lossless ? std::to_string(static_cast<unsigned>(*lossless)) : std::string("?")) + " baud (uart.baud in " +
                      profile->file.string() + ", and the SOC built for it)");
  }
  out.tty = !a.tty.empty() ? a.tty : profile->tty;
  if (out.tty.empty()) {
    auto found = usb::find_usb_tty(profile->vid, profile->pid, profile->interface, profile->serial);
    if (!found) return make_error("--board " + profile->name + ": " + found.error().message);
    out.tty = *found;
  }
  auto serial = dmc1::SerialLink::open(out.tty, profile->baud);
  if (!serial) return serial.error();
  g_send_interrupted = false;
  (*serial)->set_cancel_flag(&g_send_interrupted);
  auto previous = std::signal(SIGINT, [](int) { g_send_interrupted = true; });
  const auto t0 = std::chrono::steady_clock::now();
  auto sent = (*serial)->send(words);
  if (sent) sent = (*serial)->drain();
  std::signal(SIGINT, previous);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.sent = (*serial)->stats();
  if (!sent) return sent.error();
  return out;
}

}  // namespace

int render_dmc1(const GlobalOptions& g, const Dmc1RenderArgs& a) {
  if (a.out.empty() && a.raw.empty() && a.frames_dir.empty() && !a.timing && a.board.empty())
    return fail("nothing to produce; pass --out FILE.png (or --raw, --frames-dir, --timing, --board)", 2);
  if (!a.tty.empty() && a.board.empty()) return fail("--tty names the port of a --board; add --board NAME", 2);
  if (a.textures.empty() || a.palette.empty())
    return fail("the DMC-1 needs its texture memory and palette: pass --textures FILE and --palette FILE "
                "(tests/dmc1/data has textures.bin.gz and palette.bin)", 2);
  dmc1::DeviceOptions opt;
  opt.threads = a.threads;
  for (const auto& s : a.timing_params)
    if (auto r = dmc1::apply_timing_setting(opt.timing, s); !r) return fail(r.error().message, 2);
  auto textures = dmc1::load_texture_memory(a.textures);
  if (!textures) return fail(textures.error().message);
  auto palette = dmc1::load_palette(a.palette);
  if (!palette) return fail(palette.error().message);
  auto stream = dmc1::load_stream(a.input);
  if (!stream) return fail(stream.error().message);
  auto dev = dmc1::Device::create(opt, *textures, *palette);
  if (!dev) return fail(dev.error().message, 2);
  dmc1::Device& d = **dev;

  if (!a.frames_dir.empty()) {
    std::error_code ec;
    fs::create_directories(a.frames_dir, ec);
    if (ec) return fail("--frames-dir " + a.frames_dir + ": " + ec.message());
  }
  RawWriter raw;
  if (!a.raw.empty())
    if (auto r = raw.open(a.raw); !r) return fail(r.error().message);
  std::vector<std::uint16_t> last;
  std::vector<std::uint64_t> cycles;
  std::string frame_error;
  d.set_frame_callback([&](const dmc1::Frame& f) {
    if (raw.is_open()) raw.append(f.rgb565);
    last.assign(f.rgb565.begin(), f.rgb565.end());
    cycles.push_back(f.gpu_cycles);
    if (!a.frames_dir.empty() && frame_error.empty()) {
      char name[32];
      std::snprintf(name, sizeof name, "frame-%05u.png", f.number);
      if (auto r = save_png(fs::path(a.frames_dir) / name, dmc1::frame_image(f.rgb565)); !r) frame_error = r.error().message;
    }
  });
  const auto t0 = std::chrono::steady_clock::now();
  d.submit(stream->words);
  d.flush();
  const double elapsed_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!frame_error.empty()) return fail(frame_error);
  std::optional<BoardSend> board;
  if (!a.board.empty()) {
    if (!g.json)
      std::printf("streaming %zu commands to %s (the frames written are the simulator's: the board sends none back)\n",
                  stream->words.size(), a.board.c_str());
    auto sent = send_to_board(a, stream->words, *textures, opt.timing);
    if (!sent) return fail(sent.error().message, sent.error().code == dmc1::kSerialCancelled ? 130 : 1);
    board = std::move(*sent);
  }

  // Without a complete frame, show what the panel holds: the columns sent so far.
  const bool partial = cycles.empty();
  const unsigned columns = d.column();
  if (partial) {
    last.assign(d.screen().begin(), d.screen().end());
    if (raw.is_open()) raw.append(last);
    std::fprintf(stderr,
                 "gpubridge render: warning: %s ended after %u of 320 columns without completing a frame; the image shows "
                 "the panel (unsent columns black)\n",
                 a.input.c_str(), columns);
  } else if (columns != 0) {
    std::fprintf(stderr, "gpubridge render: warning: %s ends %u column(s) into another frame; those are not written\n",
                 a.input.c_str(), columns);
  }
  if (!a.out.empty())
    if (auto r = save_png(a.out, dmc1::frame_image(last)); !r) return fail(r.error().message);
  if (raw.is_open())
    if (auto r = raw.close(); !r) return fail(r.error().message);

  const auto& tp = opt.timing;
  const dmc1::DeviceStats& st = d.stats();
  const double words_per_frame = cycles.empty() ? static_cast<double>(stream->words.size())
                                                : static_cast<double>(stream->words.size()) / static_cast<double>(cycles.size());
  const double uart_fps = dmc1::uart_frames_per_second(words_per_frame, dmc1::kStandaloneBaud);
  nlohmann::json timing = nlohmann::json::array();
  for (std::size_t i = 0; i < cycles.size(); ++i)
    timing.push_back({{"frame", i},
                      {"gpu_cycles", cycles[i]},
                      {"gpu_ms", static_cast<double>(cycles[i]) / (tp.clock_mhz * 1e3)},
                      {"fps", tp.clock_mhz * 1e6 / static_cast<double>(cycles[i])}});
  if (g.json) {
    nlohmann::json j{{"input", a.input},
                     {"device", "dmc1"},
                     {"format", dmc1::to_string(stream->format)},
                     {"commands", stream->words.size()},
                     {"frames", cycles.size()},
                     {"partial_columns", columns},
                     {"output", a.out},
                     {"raw", a.raw},
                     {"walls", st.walls},
                     {"planes", st.planes},
                     {"terrains", st.terrains},
                     {"backgrounds", st.backgrounds},
                     {"parameters", st.parameters},
                     {"dropped_spans", st.dropped_spans},
                     {"texture_binds", st.texture_binds},
                     {"threads", d.threads()},
                     {"elapsed_ms", elapsed_ms}};
    if (board)
      j["board"] = {{"name", board->board}, {"tty", board->tty}, {"baud", board->baud}, {"bytes", board->sent.bytes},
                    {"words", board->sent.words}, {"seconds", board->seconds}, {"max_fifo", board->max_fifo}};
    if (a.timing) {
      j["timing"] = timing;
      j["clock_mhz"] = tp.clock_mhz;
      j["uart_baud"] = dmc1::kStandaloneBaud;
      j["uart_frames_per_second"] = uart_fps;
    }
    std::puts(json_text(j, 2).c_str());
    return 0;
  }
  std::printf("rendered %s (DMC-1, %s format): %zu commands, %zu frame(s) in %.2f ms\n", a.input.c_str(),
              std::string(dmc1::to_string(stream->format)).c_str(), stream->words.size(), cycles.size(), elapsed_ms);
  if (!a.out.empty()) std::printf("wrote %s: 320x240, %s\n", a.out.c_str(), partial ? "the panel (no complete frame)" : "the last frame");
  if (!a.raw.empty()) std::printf("wrote %s: %llu bytes of RGB565\n", a.raw.c_str(), static_cast<unsigned long long>(raw.written()));
  if (board)
    std::printf("sent %llu bytes (%llu words) to %s on %s at %u baud in %.2f s; the SOC's FIFO peaks at %u of %u commands\n",
                static_cast<unsigned long long>(board->sent.bytes), static_cast<unsigned long long>(board->sent.words),
                board->board.c_str(), board->tty.c_str(), board->baud, board->seconds, board->max_fifo, dmc1::kStandaloneFifoDepth);
  if (a.timing) {
    for (const auto& t : timing)
      std::printf("timing frame %s: %s GPU cycles = %.3f ms at %.1f MHz (%.1f fps)\n", json_text(t["frame"]).c_str(),
                  json_text(t["gpu_cycles"]).c_str(), t["gpu_ms"].get<double>(), tp.clock_mhz, t["fps"].get<double>());
    std::printf("UART link at %u baud: %.0f bytes per frame, %.2f frames/s\n", dmc1::kStandaloneBaud, words_per_frame * 8, uart_fps);
  }
  return 0;
}

}  // namespace gpubridge::cli
