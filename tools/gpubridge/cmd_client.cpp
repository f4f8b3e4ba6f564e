// Daemon-client commands: status, play, screenshot, reg read|write, upload, readback.
// All talk to gpubridged through the Client library (--connect unix:PATH|tcp:HOST:PORT).
#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "client_common.hpp"
#include "command_input.hpp"
#include "gpubridge/client/pacing.hpp"
#include "gpubridge/common/image.hpp"
#include "gpubridge/common/trace_files.hpp"
#include "gpubridge/dmc1/command.hpp"
#include "gpubridge/dmc1/stream.hpp"
#include "gpubridge/protocol/text_trace.hpp"
#include "gpubridge/protocol/trace.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::cli {

void add_client_options(CLI::App* sub, GlobalOptions& g, ClientOptions& o) {
  g.daemon_commands.push_back(sub);
  sub->add_option("--timeout", o.timeout_ms, "milliseconds to wait for each reply")->capture_default_str();
  sub->footer("The daemon: unix:$XDG_RUNTIME_DIR/gpubridge/gpubridge.sock unless the global options --connect "
              "unix:PATH|tcp:HOST:PORT and --token TOKEN (before or after the command) say otherwise.");
}

Result<client::Client> open_client(const GlobalOptions& g, const ClientOptions& o, const std::string& name) {
  const client::Timeout timeout{o.timeout_ms};
  auto c = client::Client::connect(g.connect, timeout);
  if (!c) return c.error();
  // No --token: the library takes $GPUBRIDGE_TOKEN or $GPUBRIDGE_TOKEN_FILE.
  if (auto r = c->handshake(name, g.token, timeout); !r) return r.error();
  return std::move(*c);
}

int fail(const char* command, const std::string& message) {
  std::fprintf(stderr, "gpubridge %s: %s\n", command, message.c_str());
  return 1;
}

std::optional<std::uint64_t> parse_number(const std::string& text) {
  std::uint64_t v = 0;
  const char* b = text.data();
  const char* e = text.data() + text.size();
  int base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    b += 2;
    base = 16;
  }
  const auto [p, ec] = std::from_chars(b, e, v, base);
  if (ec != std::errc() || p != e || b == e) return std::nullopt;
  return v;
}

ProgressBar::ProgressBar(std::string label, bool enabled) : label_(std::move(label)), enabled_(enabled && ::isatty(2)) {}
ProgressBar::~ProgressBar() {
  if (enabled_ && last_percent_ >= 0) std::fputc('\n', stderr);
}
void ProgressBar::update(std::uint64_t done, std::uint64_t total) {
  if (!enabled_ || total == 0) return;
  const int percent = static_cast<int>(done * 100 / total);
  if (percent == last_percent_) return;
  last_percent_ = percent;
  char bar[31];
  const int filled = percent * 30 / 100;
  for (int i = 0; i < 30; ++i) bar[i] = i < filled ? '#' : ' ';
  bar[30] = 0;
  std::fprintf(stderr, "\r%s [%s] %3d%% %.1f/%.1f MiB", label_.c_str(), bar, percent, done / 1048576.0, total / 1048576.0);
  std::fflush(stderr);
}


namespace {

using Clock = std::chrono::steady_clock;
constexpr std::uint64_t kMaxFileBytes = 1ull << 32;  // uploads: the 32-bit address space

std::atomic<bool> g_interrupted{false};  // executable-level: set by SIGINT during `play --loop`

void print_json(const nlohmann::json& j) { std::puts(json_text(j, 2).c_str()); }

// ------------------------------------------------------------------------------ status
int run_status(const GlobalOptions& g, const ClientOptions& o) {
  auto c = open_client(g, o, "gpubridge status");
  if (!c) return fail("status", c.error().message);
  auto s = c->status(client::Timeout{o.timeout_ms});
  if (!s) return fail("status", s.error().message);
  const auto j = nlohmann::json::parse(*s, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return fail("status", "daemon sent a status that is not a JSON object");
  c->close();
  if (g.json) {
    print_json(j);
    return 0;
  }
  std::printf("daemon:    gpubridged %s at %s, up %.0f s\n", j.value("daemon_version", "?").c_str(),
              c->address().to_string().c_str(), j.value("uptime_s", 0.0));
  // A daemon that predates device kinds serves spigpu (docs/protocol.md 17.7).
  const auto kind = protocol::parse_device_kind(j.value("device_kind", "spigpu"));
  std::printf("device:    %s\n", kind ? std::string(protocol::device_kind_info(*kind).label).c_str() : j.value("device_kind", "?").c_str());
  std::printf("backend:   %s%s%s\n", j.value("backend", "?").c_str(),
              j.value("board", "").empty() ? "" : (" board " + j.value("board", "")).c_str(),
              j.value("bridge", "").empty() ? "" : (" via " + j.value("bridge", "")).c_str());
  if (j.contains("frames_note")) std::printf("frames:    %s\n", j.value("frames_note", "").c_str());
  if (j.contains("accuracy")) std::printf("accuracy:  %s\n", j.value("accuracy", "").c_str());
  if (j["lease"].is_object())
    std::printf("lease:     session %u (%s), %zu waiting\n", j["lease"].value("session", 0u),
                j["lease"].value("name", "").c_str(), j.value("lease_waiters", std::size_t{0}));
  else
    std::printf("lease:     free\n");
  std::printf("clients:   %zu\n", j.value("client_count", std::size_t{0}));
  for (const auto& cl : j["clients"]) {
    // TCP clients: "tcp (tls)" or "tcp (plain)"; Unix socket clients: "unix".
    std::string via = cl.value("transport", "");
    if (via == "tcp") via += cl.value("encryption", "") == "tls" ? " (tls)" : " (plain)";
    std::printf("  #%-4u %-24s %-11s%s%s\n", cl.value("session", 0u), cl.value("name", "").c_str(), via.c_str(),
                cl.value("lease", false) ? " lease" : "", cl.value("subscribed", false) ? " subscribed" : "");
  }
  if (j.contains("tls") && j["tls"].is_object())
    std::printf("tls:       TCP listeners present certificate %s\n", j["tls"].value("fingerprint", "").c_str());
  std::printf("frames:    %llu scanned out, last #%u\n",
              static_cast<unsigned long long>(j["frames"].value("count", std::uint64_t{0})),
              j["frames"].value("last_number", 0u));
  // Board backends only (daemons without hot-plug omit the object or report it disabled).
  if (j.contains("hotplug") && j["hotplug"].is_object() && j["hotplug"].value("enabled", false)) {
    const auto& h = j["hotplug"];
    std::printf("hot-plug:  board %s, %llu unplug(s), %llu re-attach(es), checked every %llu ms%s\n",
                h.value("awaiting_first_board", false) ? "none yet (auto: looking for one)"
                : h.value("attached", true)            ? "attached"
                                                       : "gone (looking for it)",
                static_cast<unsigned long long>(h.value("detaches", std::uint64_t{0})),
                static_cast<unsigned long long>(h.value("reattaches", std::uint64_t{0})),
                static_cast<unsigned long long>(h.value("interval_ms", std::uint64_t{0})),
                h.value("usb_notifications", false)
                    ? (" and on USB plug/unplug (" + std::to_string(h.value("usb_events", std::uint64_t{0})) + " so far)").c_str()
                    : "");
  }
  // Mirror mode (gpubridged --mirror): board frames compared with the simulator's.
  if (j.contains("mirror") && j["mirror"].is_object() && j["mirror"].value("enabled", false)) {
    const auto& m = j["mirror"];
    const auto mismatches = m.value("mismatches", std::uint64_t{0});
    std::printf("mirror:    %llu of %llu frame(s) differ from the simulator",
                static_cast<unsigned long long>(mismatches),
                static_cast<unsigned long long>(m.value("compared", std::uint64_t{0})));
    if (mismatches && m.contains("first_mismatch") && m["first_mismatch"].is_number()) {
      std::printf(" (first #%llu", static_cast<unsigned long long>(m["first_mismatch"].get<std::uint64_t>()));
      if (m.contains("first_mismatch_pixels") && m["first_mismatch_pixels"].is_number())
        std::printf(", %llu pixel(s) differ",
                    static_cast<unsigned long long>(m["first_mismatch_pixels"].get<std::uint64_t>()));
      if (mismatches > 1 && m.contains("last_mismatch") && m["last_mismatch"].is_number()) {
        std::printf(", latest #%llu", static_cast<unsigned long long>(m["last_mismatch"].get<std::uint64_t>()));
        if (m.contains("last_mismatch_pixels") && m["last_mismatch_pixels"].is_number())
          std::printf(", %llu pixel(s) differ",
                      static_cast<unsigned long long>(m["last_mismatch_pixels"].get<std::uint64_t>()));
      }
      std::printf("; see the differences with `gpubridge screenshot --source diff`)");
    }
    std::printf("\n");
    // The decorator's own counters (daemons before they were reported omit them).
    if (m.contains("model_errors"))
      std::printf("           %llu command(s) the board accepted were refused by the simulator, "
                  "%llu swap(s) without a partner, %llu intermediate simulator swap(s) skipped\n",
                  static_cast<unsigned long long>(m.value("model_errors", std::uint64_t{0})),
                  static_cast<unsigned long long>(m.value("unpaired_frames", std::uint64_t{0})),
                  static_cast<unsigned long long>(m.value("coalesced_swaps", std::uint64_t{0})));
  }
  return 0;
}

// ------------------------------------------------------------------------------ play
struct PlayOptions {
  std::string trace;
  bool loop = false;
  unsigned repeat = 1;
  double fps = 0;
  bool fail_if_busy = false;
  unsigned window = 8;  // swaps/fences in flight (pipelined completion); --sync: a round trip each
  bool sync = false;
};

std::size_t count_swaps(protocol::FrameView v) {
  std::size_t n = 0;
  const auto display = protocol::index_of(protocol::Reg::FB_DISPLAY);
  for (std::size_t i = 0; i < v.bytes.size(); i += protocol::kFrameBytes) n += (v.bytes[i] & 0x7F) == display;
  return n;
}

// Takes the lease and arms Ctrl-C for a play.
Result<void> start_play(client::Client& c, const PlayOptions& p, client::Timeout timeout) {
  if (auto r = c.acquire_lease(p.fail_if_busy ? protocol::LeaseMode::FailIfBusy : protocol::LeaseMode::Wait,
                               p.fail_if_busy ? timeout : client::Timeout{24 * 3600 * 1000});
      !r)
    return r;
  std::signal(SIGINT, [](int) { g_interrupted = true; });
  // Ctrl-C stops at once, even inside a call waiting for the daemon (a full socket, a fence).
  c.set_interrupt_flag(&g_interrupted);
  return {};
}

bool stopped_by_ctrl_c(const Result<void>& r) { return !r && r.error().code == client::kInterrupted; }

// How a play ended: the final fence (unless Ctrl-C: closing without one makes the daemon drop the
// client's queued work and free the lease), the elapsed time, and a clean close when not interrupted.
struct PlayEnd {
  double seconds = 0;
  bool interrupted = false;
};
Result<PlayEnd> end_play(client::Client& c, const client::FramePacer& pacer, client::Timeout timeout) {
  if (!g_interrupted)
    if (auto r = c.fence(timeout); !r && !stopped_by_ctrl_c(r)) return r.error();
  PlayEnd end{pacer.elapsed_seconds(), g_interrupted.load()};
  if (!end.interrupted) c.close();
  return end;
}

client::PaceOptions pace_options(const PlayOptions& p) { return {p.fps, p.window, p.sync}; }

// A DMC-1 stream (.dmc1, .nfo: docs/dmc1.md "Stream files") to a daemon serving a DMC-1: its command
// words in DMC1_WORDS messages, one frame (320 end-of-column commands) per message, so --fps paces
// frames as it paces spigpu swaps.
int run_play_dmc1(const GlobalOptions& g, const ClientOptions& o, const PlayOptions& p) {
  auto stream = dmc1::load_stream(p.trace);
  if (!stream) return fail("play", stream.error().message);
  auto c = open_client(g, o, "gpubridge play");
  if (!c) return fail("play", c.error().message);
  if (auto r = client::require_device_kind(*c, p.trace, protocol::DeviceKind::Dmc1); !r) return fail("play", r.error().message);
  const client::Timeout timeout{o.timeout_ms};
  if (auto r = start_play(*c, p, timeout); !r) return fail("play", r.error().message);
  // Frame boundaries: after every 320th end-of-column command; the rest is one last piece.
  std::vector<std::size_t> ends;
  unsigned columns = 0;
  for (std::size_t i = 0; i < stream->words.size(); ++i)
    if (dmc1::kind_of(stream->words[i]) == dmc1::CommandKind::EndOfColumn && ++columns % dmc1::kColumns == 0) ends.push_back(i + 1);
  const std::size_t complete_frames = ends.size();
  if (ends.empty() || ends.back() != stream->words.size()) ends.push_back(stream->words.size());
  client::FramePacer pacer(*c, pace_options(p), &g_interrupted);
  std::uint64_t words = 0, frames = 0, passes = 0;
  for (unsigned pass = 0; (p.loop || pass < p.repeat) && !g_interrupted; ++pass, ++passes) {
    std::size_t from = 0;
    for (std::size_t k = 0; k < ends.size() && !g_interrupted; ++k) {
      const std::span<const std::uint64_t> piece(stream->words.data() + from, ends[k] - from);
      from = ends[k];
      if (piece.empty()) continue;
      auto r = c->write_dmc1_words(piece, timeout);
      words += piece.size();
      const bool frame = k < complete_frames;  // else the tail after the last complete frame
      frames += frame;
      if (r && frame && p.fps > 0) r = pacer.frames_sent(1, timeout);
      if (stopped_by_ctrl_c(r)) break;
      if (!r) return fail("play", r.error().message);
    }
  }
  auto end = end_play(*c, pacer, timeout);
  if (!end) return fail("play", end.error().message);
  const auto [seconds, interrupted] = *end;
  if (g.json) {
    print_json({{"trace", p.trace}, {"device_kind", "dmc1"}, {"passes", passes}, {"command_words", words},
                {"frames", frames}, {"seconds", seconds}, {"interrupted", interrupted}});
  } else {
    std::printf("%s %s: %llu DMC-1 command words, %llu frames in %.3f s\n",
                interrupted ? "stopped (Ctrl-C) after playing" : "played", p.trace.c_str(),
                static_cast<unsigned long long>(words), static_cast<unsigned long long>(frames), seconds);
  }
  return 0;
}

int run_play(const GlobalOptions& g, const ClientOptions& o, const PlayOptions& p) {
  if (auto r = client::check_pace_options(pace_options(p), "--fps"); !r) return fail("play", r.error().message);
  if (dmc1::stream_format_for_path(p.trace) || is_dmc1_binary_trace(p.trace)) return run_play_dmc1(g, o, p);
  auto stream = load_trace(p.trace);
  if (!stream) return fail("play", stream.error().message);
  auto c = open_client(g, o, "gpubridge play");
  if (!c) return fail("play", c.error().message);
  if (auto r = client::require_device_kind(*c, p.trace, protocol::DeviceKind::Spigpu); !r) return fail("play", r.error().message);
  const client::Timeout timeout{o.timeout_ms};
  if (auto r = start_play(*c, p, timeout); !r) return fail("play", r.error().message);
  auto stopped = stopped_by_ctrl_c;
  const unsigned window = p.sync ? 0 : p.window;
  client::FramePacer pacer(*c, pace_options(p), &g_interrupted);
  std::uint64_t frames = 0, swaps = 0, commands = 0, passes = 0;
  nlohmann::json reads = nlohmann::json::array();
  for (unsigned pass = 0; (p.loop || pass < p.repeat) && !g_interrupted; ++pass, ++passes) {
    for (const auto& tc : stream->commands) {
      if (g_interrupted) break;
      ++commands;
      Result<void> r;
      if (auto* f = std::get_if<protocol::FramesCmd>(&tc.command)) {
        r = c->write_frames(f->view(), timeout);
        frames += f->size();
        const auto n = count_swaps(f->view());
        swaps += n;
        // Pace on swaps: the next swap may not happen before swaps/fps seconds after the start.
        // Pipelined: a fence marks the swap and at most `window` swaps are in flight, so a link
        // with latency costs no round trip per frame; --sync waits for each swap to execute.
        if (r && n && p.fps > 0) r = pacer.frames_sent(n, timeout);
      } else if (auto* u = std::get_if<protocol::UploadCmd>(&tc.command)) {
        // Pipelined, an upload is not a round trip either (its ACK is taken when it arrives).
        r = p.sync ? c->upload(u->address, u->data, {}, timeout) : c->upload_async(u->address, u->data, timeout);
      } else if (auto* fe = std::get_if<protocol::FenceCmd>(&tc.command)) {
        (void)fe;
        r = pacer.fence(timeout);
      } else if (auto* rr = std::get_if<protocol::ReadRegCmd>(&tc.command)) {
        auto v = c->read_register(rr->index, timeout);
        if (v) {
          const auto* desc = protocol::find_register(rr->index);
          if (pass == 0)
            reads.push_back({{"register", desc ? std::string(desc->name) : std::to_string(rr->index)}, {"value", *v}});
        } else {
          r = v.error();
        }
      } else if (auto* rb = std::get_if<protocol::ReadbackCmd>(&tc.command)) {
        auto data = c->readback(rb->address, rb->length, {}, timeout);
        if (!data) r = data.error();
      }
      if (stopped(r)) break;
      if (!r) return fail("play", r.error().message);
    }
  }
  auto end = end_play(*c, pacer, timeout);
  if (!end) return fail("play", end.error().message);
  const auto [seconds, interrupted] = *end;
  if (g.json) {
    const auto& w = c->wire_stats();
    print_json({{"trace", p.trace}, {"passes", passes}, {"commands", commands}, {"register_writes", frames},
                {"swaps", swaps}, {"seconds", seconds}, {"reads", reads}, {"interrupted", interrupted},
                {"window", window}, {"compressed", c->session().compressed}, {"bytes_sent", w.bytes_sent},
                {"frame_bytes", w.frame_bytes}, {"frame_wire_bytes", w.frame_wire_bytes}});
  } else {
    for (const auto& rd : reads)
      std::printf("%s = 0x%016llx\n", rd["register"].get<std::string>().c_str(),
                  static_cast<unsigned long long>(rd["value"].get<std::uint64_t>()));
    std::printf("%s %s: %llu register writes, %llu swaps in %.3f s\n", interrupted ? "stopped (Ctrl-C) after playing" : "played",
                p.trace.c_str(), static_cast<unsigned long long>(frames), static_cast<unsigned long long>(swaps), seconds);
  }
  return 0;
}

// ------------------------------------------------------------------------------ screenshot
// The daemon's count of scanned-out frames (status "frames.count"), or nullopt when it does not say.
std::optional<std::uint64_t> scanned_out(client::Client& c, client::Timeout timeout, std::string* backend = nullptr,
                                         std::string* error = nullptr) {
  auto s = c.status(timeout);
  if (!s) {
    if (error) *error = s.error().message;
    return std::nullopt;
  }
  const auto j = nlohmann::json::parse(*s, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("frames") || !j["frames"].is_object() ||
      !j["frames"].contains("count") || !j["frames"]["count"].is_number_unsigned()) {
    if (error) *error = "its status has no frame count";
    return std::nullopt;
  }
  if (backend) *backend = j.value("backend", "");
  return j["frames"]["count"].get<std::uint64_t>();
}

// Why no frame arrived, told from what the daemon did meanwhile: it closed the connection, it scanned
// nothing out (nothing is drawing), or it scanned frames out that did not reach this client.
std::string no_frame_message(client::Client& c, const Error& error, std::optional<std::uint64_t> before,
                             unsigned received, unsigned wanted, const std::string& source, client::Timeout timeout) {
  const std::string got = received ? fmt::format(" (got {} of the {} frames --skip {} asks for)", received, wanted,
                                                 wanted - 1)
                                   : "";
  const double seconds = static_cast<double>(timeout.count()) / 1000.0;
  if (client::is_protocol_error(error, protocol::ErrorCode::ShuttingDown))
    return fmt::format("gpubridged shut down before a frame arrived{} ({})", got, error.message);
  if (error.code == client::kConnectionError)
    return fmt::format("the daemon closed the connection before a frame arrived{}: {} (did gpubridged stop or "
                       "restart? `gpubridge status` tells)",
                       got, error.message);
  if (error.code != client::kTimeoutError) return fmt::format("no frame{}: {}", got, error.message);
  std::string backend, status_error;
  const auto after = scanned_out(c, timeout, &backend, &status_error);
  if (!after)
    return fmt::format("no frame within {:g} s{}, and the daemon did not answer a status request either ({}); is "
                       "it overloaded or stuck?",
                       seconds, got, status_error);
  if (!before || *after == *before)
    return fmt::format("no frame within {:g} s{}: nothing is drawing (the daemon scanned out no frame while we "
                       "waited; {} since it started). Start a client that draws, e.g. `gpubridge play TRACE`, or "
                       "wait longer with --timeout MS",
                       seconds, got, *after);
  if (received)
    return fmt::format("only {} of the {} frames --skip {} asks for arrived within {:g} s of each other (the daemon "
                       "scanned out {} meanwhile, and a subscriber that falls behind gets the newest only)",
                       received, wanted, wanted - 1, seconds, *after - *before);
  std::string hint;
  if (backend != "sim")
    hint = " A board whose profile says \"scanout\": \"crc\" reports swaps without pixels; with gpubridged "
           "--mirror, --source sim shows the simulator's picture of them.";
  return fmt::format("the daemon scanned out {} frame(s) while we waited {:g} s, but no {} picture of them reached "
                     "this client.{}",
                     *after - *before, seconds, source, hint);
}

int run_screenshot(const GlobalOptions& g, const ClientOptions& o, const std::string& out, unsigned skip,
                   const std::string& source_name) {
  const auto source = protocol::parse_frame_source(source_name);
  if (!source) return fail("screenshot", "--source '" + source_name + "' is not a frame source (use board, sim or diff)");
  auto c = open_client(g, o, "gpubridge screenshot");
  if (!c) return fail("screenshot", c.error().message);
  const client::Timeout timeout{o.timeout_ms};
  protocol::Subscribe request{protocol::FrameFormat::RGBA8888, 0, std::nullopt};
  if (*source != protocol::FrameSource::Board) request.source = *source;  // old daemons only know board
  if (auto r = c->subscribe(request, timeout); !r) return fail("screenshot", r.error().message);
  // Counted once subscribed (every later swap is one we should get), to tell "nothing is drawing"
  // from "frames came but not to us" if none arrives.
  const auto before = scanned_out(*c, timeout);
  if (!g.json) {
    std::printf("waiting for a frame...\n");
    std::fflush(stdout);
  }
  Result<client::ReceivedFrame> f = make_error("no frame");
  for (unsigned i = 0; i <= skip; ++i) {
    f = c->next_frame(timeout);
    if (!f) return fail("screenshot", no_frame_message(*c, f.error(), before, i, skip + 1, source_name, timeout));
  }
  const auto img = image_from_device(f->format, f->width, f->height, f->pixels);
  if (auto r = save_png(out, img); !r) return fail("screenshot", r.error().message);
  c->close();
  if (g.json)
    print_json({{"out", out}, {"frame", f->number}, {"width", f->width}, {"height", f->height}, {"crc", f->crc},
                {"source", protocol::to_string(f->source)}});
  else
    std::printf("frame #%u (%ux%u, %s) written to %s\n", f->number, f->width, f->height,
                std::string(protocol::to_string(f->source)).c_str(), out.c_str());
  return 0;
}

// ------------------------------------------------------------------------------ reg read / write
Result<std::uint8_t> register_index(const std::string& text) {
  if (const auto* d = protocol::find_register(text)) return d->index;
  if (auto n = parse_number(text); n && *n < protocol::kRegisterCount) return static_cast<std::uint8_t>(*n);
  return make_error("unknown register \"" + text + "\" (use a name from `gpubridge regs` or an index 0..127)");
}

int run_reg_read(const GlobalOptions& g, const ClientOptions& o, const std::string& reg) {
  auto index = register_index(reg);
  if (!index) {
    std::fprintf(stderr, "gpubridge reg read: %s\n", index.error().message.c_str());
    return 2;
  }
  auto c = open_client(g, o, "gpubridge reg");
  if (!c) return fail("reg read", c.error().message);
  if (*index == protocol::index_of(protocol::Reg::MEM_DATA))
    if (auto r = c->acquire_lease(protocol::LeaseMode::FailIfBusy); !r) return fail("reg read", r.error().message);
  auto v = c->read_register(*index, client::Timeout{o.timeout_ms});
  if (!v) return fail("reg read", v.error().message);
  c->close();
  const auto* d = protocol::find_register(*index);
  const std::string name = d ? std::string(d->name) : "0x" + std::to_string(*index);
  if (g.json) {
    nlohmann::json j{{"register", name}, {"index", *index}, {"value", *v}};
    if (d)
      for (const auto& f : d->fields)
        if (f.width) j["fields"][std::string(f.name)] = f.get(*v);
    print_json(j);
  } else {
    std::printf("%s = 0x%016llx\n", name.c_str(), static_cast<unsigned long long>(*v));
  }
  return 0;
}

int run_reg_write(const GlobalOptions& g, const ClientOptions& o, const std::string& reg, const std::vector<std::string>& value) {
  // Same syntax as a text-trace line: `NAME VALUE`, `NAME FIELD=V ...` or `0xIDX 0xDATA`.
  auto index = register_index(reg);
  std::string line = index && protocol::find_register(*index) ? std::string(protocol::find_register(*index)->name) : reg;
  for (const auto& v : value) line += " " + v;
  auto frame = protocol::parse_register_line(line);
  if (!frame) {
    std::fprintf(stderr, "gpubridge reg write: %s\n", frame.error().message.c_str());
    return 2;
  }
  auto c = open_client(g, o, "gpubridge reg");
  if (!c) return fail("reg write", c.error().message);
  const client::Timeout timeout{o.timeout_ms};
  if (auto r = c->acquire_lease(protocol::LeaseMode::Wait, timeout); !r) return fail("reg write", r.error().message);
  const auto bytes = protocol::encode(*frame);
  if (auto r = c->write_frames(protocol::FrameView{bytes}, timeout); !r) return fail("reg write", r.error().message);
  if (auto r = c->fence(timeout); !r) return fail("reg write", r.error().message);
  c->close();
  if (g.json)
    print_json({{"index", frame->index}, {"value", frame->data}, {"written", true}});
  else
    std::printf("wrote %s\n", protocol::format_register_write(frame->index, frame->data).c_str());
  return 0;
}

// ------------------------------------------------------------------------------ upload / readback
int run_upload(const GlobalOptions& g, const ClientOptions& o, const std::string& addr_text, const std::string& file) {
  auto addr = parse_number(addr_text);
  if (!addr || *addr > 0xFFFFFFFFull) {
    std::fprintf(stderr, "gpubridge upload: address \"%s\" must be a number 0..0xFFFFFFFF\n", addr_text.c_str());
    return 2;
  }
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) return fail("upload", "cannot open " + file);
  const auto size = static_cast<std::uint64_t>(in.tellg());
  if (size == 0) return fail("upload", file + " is empty");
  if (size > kMaxFileBytes - *addr) return fail("upload", file + " does not fit below the 4 GiB address limit");
  std::vector<std::uint8_t> data(static_cast<std::size_t>(size));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(size));
  if (!in) return fail("upload", "cannot read " + file);
  auto c = open_client(g, o, "gpubridge upload");
  if (!c) return fail("upload", c.error().message);
  const client::Timeout timeout{o.timeout_ms};
  if (auto r = c->acquire_lease(protocol::LeaseMode::Wait, timeout); !r) return fail("upload", r.error().message);
  ProgressBar bar("upload", !g.json);
  const auto start = Clock::now();
  if (auto r = c->upload(static_cast<std::uint32_t>(*addr), data, [&](auto d, auto t) { bar.update(d, t); }, timeout); !r)
    return fail("upload", r.error().message);
  const double s = std::chrono::duration<double>(Clock::now() - start).count();
  c->close();
  if (g.json)
    print_json({{"address", *addr}, {"bytes", size}, {"seconds", s}});
  else
    std::printf("uploaded %llu bytes to 0x%llx in %.3f s\n", static_cast<unsigned long long>(size),
                static_cast<unsigned long long>(*addr), s);
  return 0;
}

int run_readback(const GlobalOptions& g, const ClientOptions& o, const std::string& addr_text, const std::string& len_text,
                 const std::string& out) {
  auto addr = parse_number(addr_text);
  auto len = parse_number(len_text);
  if (!addr || *addr > 0xFFFFFFFFull || !len || *len == 0 || *len > 0xFFFFFFFFull - *addr) {
    std::fprintf(stderr, "gpubridge readback: ADDR and LEN must be numbers with LEN ≥ 1 and ADDR+LEN ≤ 4 GiB\n");
    return 2;
  }
  auto c = open_client(g, o, "gpubridge readback");
  if (!c) return fail("readback", c.error().message);
  const client::Timeout timeout{o.timeout_ms};
  if (auto r = c->acquire_lease(protocol::LeaseMode::Wait, timeout); !r) return fail("readback", r.error().message);
  ProgressBar bar("readback", !g.json);
  auto data = c->readback(static_cast<std::uint32_t>(*addr), static_cast<std::uint32_t>(*len),
                          [&](auto d, auto t) { bar.update(d, t); }, timeout);
  if (!data) return fail("readback", data.error().message);
  c->close();
  std::ofstream f(out, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(data->data()), static_cast<std::streamsize>(data->size()));
  if (!f) return fail("readback", "cannot write " + out);
  if (g.json)
    print_json({{"address", *addr}, {"bytes", data->size()}, {"out", out}});
  else
    std::printf("read %zu bytes from 0x%llx into %s\n", data->size(), static_cast<unsigned long long>(*addr), out.c_str());
  return 0;
}

}  // namespace

GPUBRIDGE_COMMAND("client", 40, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  auto copts = std::make_shared<ClientOptions>();

  auto* status = app.add_subcommand(
      "status", "show the daemon's backend, lease holder, clients, frame counter and its hot-plug and mirror counters");
  add_client_options(status, g, *copts);
  runners.emplace_back(status, [&g, copts] { return run_status(g, *copts); });

  auto popts = std::make_shared<PlayOptions>();
  auto* play = app.add_subcommand("play", "stream a text or binary trace, or a DMC-1 stream, to the daemon (holding the device lease)");
  play->add_option("TRACE", popts->trace,
                   "trace file (.trace/.txt text or .gbt binary) for a spigpu daemon, or a DMC-1 stream (.dmc1, .nfo) "
                   "for a daemon serving a DMC-1")->required()->check(CLI::ExistingFile);
  play->add_flag("--loop", popts->loop, "repeat until interrupted (Ctrl-C)");
  play->add_option("--repeat", popts->repeat, "play the trace N times")->check(CLI::Range(1u, 1000000u));
  play->add_option("--fps", popts->fps,
                   "at most N swaps (FB_DISPLAY writes; DMC-1: frames of 320 columns) per second; 0 = as fast as possible");
  play->add_flag("--no-wait", popts->fail_if_busy, "fail with BUSY instead of waiting when another client draws");
  play->add_option("--window", popts->window,
                   "trace fences and --fps swaps kept in flight: the next waits only when N are unfinished, so a "
                   "remote daemon costs no round trip per frame")
      ->check(CLI::Range(1u, 1024u))
      ->capture_default_str();
  play->add_flag("--sync", popts->sync, "wait for every trace fence and paced swap to execute (one round trip each)");
  add_client_options(play, g, *copts);
  runners.emplace_back(play, [&g, copts, popts] { return run_play(g, *copts, *popts); });

  auto out = std::make_shared<std::string>();
  auto skip = std::make_shared<unsigned>(0);
  auto* shot = app.add_subcommand("screenshot", "save the next scanned-out frame as a PNG");
  shot->add_option("--out,-o", *out, "PNG file to write")->required();
  shot->add_option("--skip", *skip, "ignore this many frames first");
  auto source = std::make_shared<std::string>("board");
  shot->add_option("--source", *source,
                   "board (what the device scanned out), or with gpubridged --mirror: sim (the simulator's frame "
                   "for the same swap) or diff (differing pixels magenta)")
      ->capture_default_str()
      ->check(CLI::IsMember({"board", "sim", "diff"}));
  add_client_options(shot, g, *copts);
  runners.emplace_back(shot, [&g, copts, out, skip, source] {
    return run_screenshot(g, *copts, *out, *skip, *source);
  });

  auto* reg = app.add_subcommand("reg", "read or write one device register through the daemon");
  reg->require_subcommand(1);
  auto reg_name = std::make_shared<std::string>();
  auto reg_value = std::make_shared<std::vector<std::string>>();
  auto* rd = reg->add_subcommand("read", "read a register: reg read NAME|INDEX");
  rd->add_option("REGISTER", *reg_name, "register name (see `gpubridge regs`) or index")->required();
  add_client_options(rd, g, *copts);
  runners.emplace_back(rd, [&g, copts, reg_name] { return run_reg_read(g, *copts, *reg_name); });
  auto* wr = reg->add_subcommand("write", "write a register: reg write NAME|INDEX VALUE | FIELD=V ...");
  wr->add_option("REGISTER", *reg_name, "register name or index")->required();
  wr->add_option("VALUE", *reg_value, "a number (0x.. hex) or FIELD=VALUE pairs, as in text traces")->required();
  add_client_options(wr, g, *copts);
  runners.emplace_back(wr, [&g, copts, reg_name, reg_value] { return run_reg_write(g, *copts, *reg_name, *reg_value); });

  auto addr = std::make_shared<std::string>();
  auto file = std::make_shared<std::string>();
  auto* up = app.add_subcommand("upload", "copy a file into device memory: upload ADDR FILE");
  up->add_option("ADDR", *addr, "device byte address (decimal or 0x hex)")->required();
  up->add_option("FILE", *file, "bytes to upload")->required();
  add_client_options(up, g, *copts);
  runners.emplace_back(up, [&g, copts, addr, file] { return run_upload(g, *copts, *addr, *file); });

  auto len = std::make_shared<std::string>();
  auto* rb = app.add_subcommand("readback", "copy device memory into a file: readback ADDR LEN --out FILE");
  rb->add_option("ADDR", *addr, "device byte address")->required();
  rb->add_option("LEN", *len, "number of bytes")->required();
  rb->add_option("--out,-o", *file, "file to write")->required();
  add_client_options(rb, g, *copts);
  runners.emplace_back(rb, [&g, copts, addr, len, file] { return run_readback(g, *copts, *addr, *len, *file); });
});

}  // namespace gpubridge::cli
