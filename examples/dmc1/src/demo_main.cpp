// gpubridge-dmc1-demo: the DMC-1 example client. `stream` sends the moving camera's frames to a
// gpubridged serving a DMC-1 (gpubridge-view shows them); `write` saves frames along the camera path
// as a DMC-1 stream (.dmc1 text or tinygpus .nfo lines) for `gpubridge render --device dmc1` or a
// board; `goldens` renders the golden frames on the DMC-1 simulator and checks (or with --write,
// rewrites) examples/dmc1/golden/.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "gpubridge/client/client.hpp"
#include "gpubridge/client/pacing.hpp"
#include "gpubridge/common/image.hpp"
#include "gpubridge/common/json_text.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/dmc1/stream.hpp"
#include "gpubridge/examples/dmc1_level.hpp"

namespace {

using namespace gpubridge;
namespace level = examples::dmc1_level;

int fail(const std::string& msg, int code = 1) {
  std::fprintf(stderr, "gpubridge-dmc1-demo: %s\n", msg.c_str());
  return code;
}

// Which frames of the camera path to send or write.
struct PathOptions {
  unsigned frames = 1;
  unsigned first = 0;  // position on the path of the first frame
  unsigned path_frames = level::kPathFrames;
};

int write_stream(const std::string& out, const PathOptions& path) {
  const auto lv = level::hall();
  std::vector<std::uint64_t> words;
  for (unsigned f = path.first; f < path.first + path.frames; ++f) {
    const auto frame = level::lap_frame_commands(lv, f, path.path_frames);
    words.insert(words.end(), frame.begin(), frame.end());
  }
  if (auto r = dmc1::save_stream(out, words); !r) return fail(r.error().message);
  std::printf("wrote %s: %u frame(s), %zu commands\n", out.c_str(), path.frames, words.size());
  return 0;
}

struct StreamOptions {
  std::string address, token;  // empty: $GPUBRIDGE_ADDRESS / $GPUBRIDGE_TOKEN, else the default socket
  client::PaceOptions pace{30, 4, false};
  bool loop = false;
  unsigned timeout_ms = 10000;
};

std::atomic<bool> g_interrupted{false};  // set by SIGINT: stop after the frame being sent

// The level to a daemon serving a DMC-1, one DMC1_WORDS message per frame (320 columns), each frame
// computed as it is sent, paced as `gpubridge play` paces: a fence per frame with a window in flight.
int stream(const PathOptions& path, const StreamOptions& o, bool json) {
  const client::Timeout timeout{o.timeout_ms};
  auto c = client::Client::connect(o.address, timeout);
  if (!c) return fail("cannot stream to the daemon: " + c.error().message + " (the level needs a daemon serving a DMC-1: gpubridged --backend dmc1)");
  if (auto r = c->handshake("gpubridge-dmc1-demo", o.token, timeout); !r) return fail("cannot stream to the daemon: " + r.error().message);
  if (auto r = client::require_device_kind(*c, "the DMC-1 example level", protocol::DeviceKind::Dmc1); !r)
    return fail(r.error().message);
  // Another client may be drawing: wait for the lease as `gpubridge play` does.
  if (auto r = c->acquire_lease(protocol::LeaseMode::Wait, client::Timeout{24 * 3600 * 1000}); !r)
    return fail("cannot take the device lease: " + r.error().message);
  std::signal(SIGINT, [](int) { g_interrupted = true; });
  c->set_interrupt_flag(&g_interrupted);
  const auto lv = level::hall();
  client::FramePacer pacer(*c, o.pace, &g_interrupted);
  std::uint64_t frames = 0, commands = 0;
  for (unsigned n = 0; (o.loop || n < path.frames) && !g_interrupted; ++n) {
    const auto words = level::lap_frame_commands(lv, path.first + n, path.path_frames);
    auto r = c->write_dmc1_words(words, timeout);
    if (r) r = pacer.frames_sent(1, timeout);
    if (!r && r.error().code == client::kInterrupted) break;
    if (!r) return fail("streaming frame " + std::to_string(path.first + n) + ": " + r.error().message);
    ++frames;
    commands += words.size();
  }
  // The last fence: every frame has been drawn (Ctrl-C: closing without it makes the daemon drop
  // what is queued and free the lease at once).
  const bool interrupted = g_interrupted;
  if (!interrupted)
    if (auto r = c->fence(timeout); !r) return fail(r.error().message);
  const double seconds = pacer.elapsed_seconds();
  const std::uint64_t bytes = c->wire_stats().bytes_sent;
  const std::string address = c->address().to_string();
  if (!interrupted) c->close();
  const double fps = seconds > 0 ? static_cast<double>(frames) / seconds : 0;
  if (json) {
    std::puts(json_text(nlohmann::json{{"address", address}, {"frames", frames}, {"commands", commands}, {"bytes", bytes},
                                       {"seconds", seconds}, {"fps", fps}, {"window", o.pace.sync ? 0 : o.pace.window},
                                       {"interrupted", interrupted}},
                        2)
                  .c_str());
  } else {
    std::printf("%s %llu frame(s) of the DMC-1 level to %s: %llu commands, %llu bytes in %.2f s (%.1f frames/s)\n",
                interrupted ? "stopped (Ctrl-C) after streaming" : "streamed", static_cast<unsigned long long>(frames),
                address.c_str(), static_cast<unsigned long long>(commands), static_cast<unsigned long long>(bytes), seconds, fps);
  }
  return 0;
}

int goldens(const std::string& dir, const std::string& textures, const std::string& palette, bool write) {
  auto mem = dmc1::load_texture_memory(textures);
  if (!mem) return fail(mem.error().message);
  auto pal = dmc1::load_palette(palette);
  if (!pal) return fail(pal.error().message);
  int status = 0;
  for (const unsigned f : level::kGoldenFrames) {
    auto dev = dmc1::Device::create({}, *mem, *pal);
    if (!dev) return fail(dev.error().message);
    Image img;
    (*dev)->set_frame_callback([&](const dmc1::Frame& fr) { img = dmc1::frame_image(fr.rgb565); });
    (*dev)->submit(level::golden_frame_commands(f));
    const auto path = std::filesystem::path(dir) / level::golden_name(f);
    if (write) {
      if (auto r = save_png(path, img); !r) return fail(r.error().message);
      std::printf("wrote %s\n", path.c_str());
      continue;
    }
    auto want = load_png(path);
    if (!want) return fail(want.error().message);
    const bool same = *want == img;
    std::printf("%s %s\n", same ? "same     " : "DIFFERENT", path.c_str());
    if (!same) status = 1;
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"gpubridge-dmc1-demo: a small level (walls, floor and ceiling planes, a terrain) ray-cast into DMC-1 spans"};
  app.require_subcommand(1);
  app.footer("Streaming: start `gpubridged --backend dmc1` and `gpubridge-view`, then `gpubridge-dmc1-demo stream`.");
  bool json = false;
  PathOptions write_path, stream_path;
  stream_path.frames = level::kPathFrames;
  const auto add_path_options = [](CLI::App* sub, PathOptions& p, const char* frames_help) {
    sub->add_option("--frames", p.frames, frames_help)->check(CLI::Range(1u, 1000000u))->capture_default_str();
    sub->add_option("--first", p.first, "first frame (position on the path)")
        ->check(CLI::Range(0u, 1000000u))
        ->capture_default_str();
    sub->add_option("--path-frames", p.path_frames, "frames per lap of the camera path")
        ->check(CLI::Range(1u, 100000u))
        ->capture_default_str();
  };

  auto* send = app.add_subcommand("stream", "stream the moving camera's frames to a gpubridged serving a DMC-1 "
                                            "(gpubridged --backend dmc1); gpubridge-view shows them");
  StreamOptions so;
  add_path_options(send, stream_path, "frames to send (one lap by default)");
  send->add_flag("--loop", so.loop, "go round the path until interrupted (Ctrl-C)");
  send->add_option("--fps", so.pace.fps, "frames per second (0 = as fast as the daemon draws them)")
      ->capture_default_str();  // checked after parsing by the client library (CLI11's Range lets NaN through)
  send->add_option("--window", so.pace.window, "frames in flight before the next waits for the daemon (pipelined fences)")
      ->check(CLI::Range(1u, 1024u))
      ->capture_default_str();
  send->add_flag("--sync", so.pace.sync, "wait for every frame to be drawn before the next (a round trip each)");
  send->add_option("--connect", so.address,
                   "daemon address: unix:PATH, tcp:HOST:PORT or tls:HOST:PORT (default: $GPUBRIDGE_ADDRESS, else the "
                   "default socket)");
  send->add_option("--token", so.token, "access token for a daemon that requires one (default: $GPUBRIDGE_TOKEN)");
  send->add_option("--timeout", so.timeout_ms, "milliseconds to wait for each reply")->capture_default_str();
  send->add_flag("--json", json, "print the summary as JSON");

  auto* write = app.add_subcommand("write", "write frames along the camera path as a DMC-1 stream file");
  std::string out;
  write->add_option("--out,-o", out, "stream file (.dmc1 text, .nfo lines)")->required();
  add_path_options(write, write_path, "frames to write");
  auto* gold = app.add_subcommand("goldens", "render the golden frames on the DMC-1 simulator and compare them with DIR");
  std::string dir = "examples/dmc1/golden", textures = "tests/dmc1/data/textures.bin.gz", palette = "tests/dmc1/data/palette.bin";
  bool rewrite = false;
  gold->add_option("--dir", dir, "golden directory")->capture_default_str();
  gold->add_option("--textures", textures, "texture memory image")->capture_default_str();
  gold->add_option("--palette", palette, "palette")->capture_default_str();
  gold->add_flag("--write", rewrite, "rewrite the goldens (only when the rendering legitimately changed)");
  CLI11_PARSE(app, argc, argv);
  if (send->parsed()) {
    if (auto r = client::check_pace_options(so.pace, "--fps"); !r) return fail(r.error().message, 2);
    return stream(stream_path, so, json);
  }
  if (write->parsed()) return write_stream(out, write_path);
  return goldens(dir, textures, palette, rewrite);
}
