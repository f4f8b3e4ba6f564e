// `gpubridge bench remote`: the examples streamed to gpubridged over loopback TCP and through a
// proxy that adds a 50 ms round trip (and optionally a bandwidth limit), side by side in one run:
// frame rates of `play` (a recorded trace of each example, paced by --fps) and of the drawing
// API's stream (gpubridge-demo stream), pipelined (a window of frames in flight) and --sync,
// without and with zstd compression; bytes on the wire per frame and the frame rate each link
// speed allows. docs/daemon.md "Remote use" reports the figures.
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench_group.hpp"
#include "client_common.hpp"
#include "daemon_child.hpp"
#include "gpubridge/bench/delay_proxy.hpp"
#include "gpubridge/common/json_text.hpp"
#include "gpubridge/common/trace_files.hpp"
#include "gpubridge/draw/client_sink.hpp"
#include "gpubridge/examples/example.hpp"

namespace gpubridge::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct RemoteOptions {
  std::string daemon, backend = "sim";
  std::vector<std::string> examples;
  unsigned frames = 60;
  double fps = 60;
  unsigned window = 4;
  unsigned rtt_ms = 50;
  double mbit = 20;  // the bandwidth-limited link
};

struct Link {
  std::string name;
  std::string address;
};

struct Run {
  double fps = 0;
  double wire_bytes_per_frame = 0;
};

// The example's frames as the drawing API sends them (what play replays).
Result<protocol::CommandStream> record(examples::Example& ex, unsigned frames) {
  draw::RecordingSink sink;
  auto ctx = draw::Context::create(sink, ex.options());
  if (!ctx) return ctx.error();
  if (auto r = examples::run_frames(ex, *ctx, 0, frames); !r) return r.error();
  return sink.take();
}

// gpubridge-demo stream, in-process: Context on a ClientSink, paced at fps.
Result<Run> stream(examples::Example& ex, const std::string& address, const RemoteOptions& o, bool sync, bool zstd) {
  auto c = client::Client::connect(address);
  if (!c) return c.error();
  if (auto h = c->handshake("bench remote", {}, client::kDefaultTimeout,
                            zstd ? client::Compression::Zstd : client::Compression::None);
      !h)
    return h.error();
  if (auto l = c->acquire_lease(); !l) return l.error();
  draw::ClientSink sink(*c);
  auto options = ex.options();
  options.frames_in_flight = sync ? 0 : o.window;
  auto ctx = draw::Context::create(sink, options);
  if (!ctx) return ctx.error();
  if (auto r = ctx->flush(); !r) return r.error();  // setup (textures) is not part of the frame rate
  const auto start = Clock::now();
  const auto wire0 = c->wire_stats().bytes_sent;
  auto r = examples::run_frames(ex, *ctx, 0, o.frames, [&](unsigned n) -> Result<void> {
    if (sync)
      if (auto f = ctx->flush(); !f) return f;
    std::this_thread::sleep_until(start + std::chrono::duration<double>((n + 1) / o.fps));
    return {};
  });
  if (!r) return r.error();
  if (auto f = ctx->flush(); !f) return f.error();
  const double secs = std::chrono::duration<double>(Clock::now() - start).count();
  Run out{o.frames / secs, double(c->wire_stats().bytes_sent - wire0) / o.frames};
  c->close();
  return out;
}

// gpubridge play of the recorded trace, as a child process (exactly what users run).
Result<Run> play(const std::string& trace, const std::string& address, const RemoteOptions& o, bool sync, bool zstd,
                 unsigned swaps) {
  std::error_code ec;
  const std::string self = fs::read_symlink("/proc/self/exe", ec).string();
  std::vector<std::string> args{self, "play", trace, "--connect", address, "--fps", std::to_string(o.fps), "--json",
                                "--window", std::to_string(o.window)};
  if (sync) args.push_back("--sync");
  int out[2];
  if (::pipe2(out, O_CLOEXEC) != 0) return make_error("pipe failed");
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(out[1], 1);
    ::setenv("GPUBRIDGE_COMPRESS", zstd ? "zstd" : "none", 1);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(out[1]);
  std::string text;
  char buf[4096];
  for (ssize_t n; (n = ::read(out[0], buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
  ::close(out[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const auto j = nlohmann::json::parse(text, nullptr, false);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !j.is_object()) return make_error("play failed: " + text);
  return Run{swaps / j["seconds"].get<double>(), j["bytes_sent"].get<double>() / swaps};
}

int run(const GlobalOptions& g, const RemoteOptions& o) {
  const fs::path dir = fs::temp_directory_path() / ("gpubridge-bench-remote-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  DaemonChild daemon;
  auto eps = daemon.start(find_daemon(o.daemon), {"--listen", "tcp:127.0.0.1:0", "--backend", o.backend, "--log-level",
                                                  "error", "--tls-dir", (dir / "tls").string()});
  if (!eps || eps->empty()) return fail("bench remote", eps ? "no endpoint" : eps.error().message);
  const auto port = static_cast<std::uint16_t>(std::stoi(eps->front().substr(eps->front().rfind(':') + 1)));
  const auto one_way = std::chrono::microseconds(o.rtt_ms * 500);
  bench::DelayProxy delayed(port, one_way);
  bench::DelayProxy narrow(port, one_way, static_cast<std::uint64_t>(o.mbit * 1e6 / 8));
  const std::string rtt = std::to_string(o.rtt_ms) + " ms";
  const Link loopback{"loopback", eps->front()};
  const Link far{rtt, "tcp:127.0.0.1:" + std::to_string(delayed.port())};
  const Link thin{rtt + " + " + fmt::format("{:g}", o.mbit) + " Mbit/s", "tcp:127.0.0.1:" + std::to_string(narrow.port())};
  struct Config {
    const Link* link;
    bool sync, zstd;
    std::string label;
  };
  const std::vector<Config> configs{{&loopback, false, false, "loopback"},
                                    {&far, true, false, rtt + " sync"},
                                    {&far, false, false, rtt + " window"},
                                    {&far, false, true, rtt + " window zstd"},
                                    {&thin, false, false, thin.name + " window"},
                                    {&thin, false, true, thin.name + " window zstd"}};
  nlohmann::json results = nlohmann::json::array();
  std::vector<std::unique_ptr<examples::Example>> list;
  if (o.examples.empty()) list = examples::make_examples();
  for (const auto& n : o.examples)
    if (auto e = examples::make_example(n)) list.push_back(std::move(e));
    else return fail("bench remote", "unknown example " + n);
  if (!g.json)
    std::printf("%u frames per run at --fps %g, window %u; frames/s of play | stream per configuration\n", o.frames, o.fps,
                o.window);
  for (auto& ex : list) {
    const std::string name = ex->info().name;
    auto rec = record(*ex, o.frames);
    if (!rec) return fail("bench remote", name + ": " + rec.error().message);
    const std::string trace = (dir / (name + ".gbt")).string();
    if (auto s = save_trace(trace, *rec); !s) return fail("bench remote", s.error().message);
    // Bytes per frame: what the frames are, and what zstd makes of them (message by message).
    std::uint64_t raw = 0, packed = 0;
    protocol::FrameDeflater deflater;
    std::vector<std::uint8_t> out;
    for (const auto& c : rec->commands)
      if (auto* f = std::get_if<protocol::FramesCmd>(&c.command)) {
        raw += f->bytes.size() + protocol::kHeaderBytes;
        packed += (deflater.deflate(f->view(), out) ? out.size() + 5 : f->bytes.size()) + protocol::kHeaderBytes;
      } else if (auto* u = std::get_if<protocol::UploadCmd>(&c.command)) {
        raw += u->data.size() + 16;
        packed += u->data.size() + 16;
      }
    const double raw_pf = double(raw) / o.frames, z_pf = double(packed) / o.frames;
    nlohmann::json row{{"example", name},
                       {"bytes_per_frame", raw_pf},
                       {"zstd_bytes_per_frame", z_pf},
                       {"compression_ratio", raw_pf / z_pf},
                       {"fps_at_100mbit", {{"plain", 100e6 / 8 / raw_pf}, {"zstd", 100e6 / 8 / z_pf}}},
                       {"fps_at_20mbit", {{"plain", 20e6 / 8 / raw_pf}, {"zstd", 20e6 / 8 / z_pf}}}};
    if (!g.json)
      std::printf("%-10s %8.0f B/frame, zstd %7.0f (x%.1f); 100 Mbit/s: %6.0f | %6.0f fps, 20 Mbit/s: %5.0f | %5.0f fps "
                  "(plain | zstd)\n",
                  name.c_str(), raw_pf, z_pf, raw_pf / z_pf, 100e6 / 8 / raw_pf, 100e6 / 8 / z_pf, 20e6 / 8 / raw_pf,
                  20e6 / 8 / z_pf);
    nlohmann::json runs = nlohmann::json::array();
    for (const auto& cfg : configs) {
      auto p = play(trace, cfg.link->address, o, cfg.sync, cfg.zstd, o.frames);
      if (!p) return fail("bench remote", name + " " + cfg.label + ": " + p.error().message);
      auto s = stream(*ex, cfg.link->address, o, cfg.sync, cfg.zstd);
      if (!s) return fail("bench remote", name + " " + cfg.label + ": " + s.error().message);
      runs.push_back({{"config", cfg.label},
                      {"play_fps", p->fps},
                      {"stream_fps", s->fps},
                      {"play_wire_bytes_per_frame", p->wire_bytes_per_frame},
                      {"stream_wire_bytes_per_frame", s->wire_bytes_per_frame}});
      if (!g.json)
        std::printf("  %-28s play %6.1f | stream %6.1f fps   (%.0f | %.0f B/frame on the wire)\n", cfg.label.c_str(),
                    p->fps, s->fps, p->wire_bytes_per_frame, s->wire_bytes_per_frame);
    }
    row["runs"] = runs;
    results.push_back(row);
  }
  daemon.stop();
  std::error_code ec;
  fs::remove_all(dir, ec);
  if (g.json)
    std::puts(json_text(nlohmann::json{{"frames", o.frames}, {"fps", o.fps}, {"window", o.window}, {"rtt_ms", o.rtt_ms},
                                       {"mbit", o.mbit}, {"backend", o.backend}, {"examples", results}},
                        2)
                  .c_str());
  return 0;
}

}  // namespace

GPUBRIDGE_COMMAND("bench-remote", 84, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  auto* sub = bench_group(app)->add_subcommand(
      "remote", "the examples through a link with latency (and a bandwidth limit): play and stream frame rates beside "
                "loopback's, pipelined and --sync, with and without compression; bytes per frame");
  auto o = std::make_shared<RemoteOptions>();
  sub->add_option("EXAMPLES", o->examples, "example names (default: all)");
  sub->add_option("--daemon", o->daemon, "gpubridged executable (default: next to gpubridge, then PATH)");
  sub->add_option("--backend", o->backend, "the daemon's backend")->capture_default_str();
  sub->add_option("--frames", o->frames, "frames per run")->check(CLI::Range(2u, 100000u))->capture_default_str();
  sub->add_option("--fps", o->fps, "pace of play and stream")->check(CLI::Range(1.0, 1000.0))->capture_default_str();
  sub->add_option("--window", o->window, "frames in flight (play --window, ContextOptions::frames_in_flight)")
      ->check(CLI::Range(1u, 1024u))
      ->capture_default_str();
  sub->add_option("--rtt-ms", o->rtt_ms, "round trip the proxy adds")->check(CLI::Range(0u, 2000u))->capture_default_str();
  sub->add_option("--mbit", o->mbit, "bandwidth of the limited link (Mbit/s)")->check(CLI::Range(0.1, 10000.0))->capture_default_str();
  runners.emplace_back(sub, [&g, o] { return run(g, *o); });
});

}  // namespace gpubridge::cli
