// gpubridged: serves the spigpu socket protocol over Unix/TCP sockets and routes it to the
// simulator or a board (see docs/daemon.md). Prints "listening on ADDRESS" per endpoint and
// "ready" on stdout once it accepts connections.
#include <cstdio>
#include <functional>
#include <optional>
#include <thread>

#include <CLI/CLI.hpp>

#ifdef GPUBRIDGE_HAVE_SYSTEMD
#include <systemd/sd-daemon.h>
#endif

#include <nlohmann/json.hpp>

#include "gpubridge/client/address.hpp"
#include "gpubridge/common/json_text.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/daemon/backend_factory.hpp"
#include "gpubridge/daemon/config.hpp"
#include "gpubridge/daemon/hub.hpp"
#include "gpubridge/daemon/mirror_backend.hpp"
#include "gpubridge/daemon/server.hpp"
#include "gpubridge/daemon/tls_identity.hpp"
#include "gpubridge/version.hpp"

namespace {

using namespace gpubridge;
namespace asio = boost::asio;

void notify(const char* state) {
#ifdef GPUBRIDGE_HAVE_SYSTEMD
  sd_notify(0, state);
#else
  (void)state;
#endif
}

int run(daemon::DaemonConfig cfg) {
  auto log = logger("daemon");
  auto backend = daemon::make_backend(cfg.backend, cfg);
  if (!backend) {
    std::fprintf(stderr, "gpubridged: %s\n", backend.error().message.c_str());
    return 1;
  }
  if (cfg.mirror) {  // the board behind a decorator that feeds the simulator the same commands
    backend = daemon::make_mirror(std::move(*backend));
    if (!backend) {
      std::fprintf(stderr, "gpubridged: %s\n", backend.error().message.c_str());
      return 2;
    }
  }
  asio::io_context net(1);
  asio::io_context device(1);
  auto device_guard = asio::make_work_guard(device);
  std::thread device_thread([&device] { device.run(); });
  auto join_device = [&] {
    device_guard.reset();
    device.stop();
    if (device_thread.joinable()) device_thread.join();
  };

  daemon::HubOptions opts;
  opts.limits = cfg.limits;
  opts.token = cfg.token;
  opts.frames_dir = cfg.frames_dir;
  opts.record_dir = cfg.record_dir;
  opts.mirror = cfg.mirror;
  // TCP listeners speak TLS with the daemon's own key, created on first start (tls_identity.hpp).
  // A listener other machines can reach (or one given as tls:) needs it: without a key the daemon
  // does not start. Loopback-only TCP serves plain clients (and SSH tunnels) without one.
  std::optional<daemon::TlsIdentity> tls;
  bool tcp = false, tls_needed = false;
  for (const auto& text : cfg.listen) {
    const auto a = client::parse_address(text);
    tcp = tcp || a->kind == client::Address::Kind::Tcp;
    tls_needed = tls_needed || (a->kind == client::Address::Kind::Tcp && (a->tls || !client::is_loopback_host(a->host)));
  }
  if (tcp) {
    auto id = daemon::load_or_create_tls_identity(cfg.tls_dir.empty() ? daemon::default_tls_dir() : cfg.tls_dir);
    if (id) {
      tls = std::move(*id);
      opts.tls_fingerprint = tls->fingerprint;
    } else if (tls_needed) {
      std::fprintf(stderr, "gpubridged: %s (set tls_dir / --tls-dir to a directory of your own)\n", id.error().message.c_str());
      join_device();
      return 1;
    } else {
      log->warn("no TLS on the loopback TCP listeners: {}", id.error().message);
    }
  }
  const daemon::Hub::BackendFactory fallback = daemon::fallback_factory(cfg);
  int exit_code = 0;
  {
    daemon::Hub hub(net.get_executor(), device.get_executor(), std::move(*backend), opts, fallback);
    // Board backends: probe presence and re-attach after an unplug; `auto` that started on the
    // simulator keeps looking for a first board the same way (sim/fake/discard: no factory).
    auto reattach = daemon::make_reattach_factory(cfg);
    if (reattach && cfg.mirror)  // a board that comes back is mirrored again
      reattach = [inner = std::move(reattach)]() -> Result<std::unique_ptr<backends::Backend>> {
        auto board = inner();
        if (!board) return board;
        return daemon::make_mirror(std::move(*board));
      };
    hub.enable_hotplug(std::move(reattach), std::chrono::milliseconds(cfg.reattach_interval_ms));
    // Plugs and unplugs of the board's USB ids wake the hot-plug step at once; polling stays the
    // fallback (and finds an adapter udev had not yet made accessible when it was announced).
    // Declared after the hub: stopped before it goes.
    auto usb_watch = daemon::watch_board_usb(cfg, [&hub] { hub.hotplug_event(); });
    if (!usb_watch)
      log->info("hot-plug: no USB notifications ({}); checking every {} ms", usb_watch.error().message,
                cfg.reattach_interval_ms);
    hub.set_hotplug_notifications(usb_watch && *usb_watch);
    daemon::Server server(net, hub);
    if (tls) {
      if (auto r = server.enable_tls(tls->key_path, tls->cert_path); !r) {
        std::fprintf(stderr, "gpubridged: %s\n", r.error().message.c_str());
        join_device();
        return 1;
      }
      // Clients pin this (tls: addresses); print it where the operator sees it.
      std::printf("tls fingerprint %s%s\n", tls->fingerprint.c_str(), tls->created ? " (new key)" : "");
      log->info("TLS certificate {} ({}){}", tls->cert_path, tls->fingerprint, tls->created ? ", generated now" : "");
    }
    for (const auto& text : cfg.listen) {
      auto addr = client::parse_address(text);
      auto bound = addr ? server.listen(*addr) : Result<client::Address>(addr.error());
      if (!bound) {
        std::fprintf(stderr, "gpubridged: %s\n", bound.error().message.c_str());
        server.stop();
        join_device();
        return 1;
      }
      std::printf("listening on %s\n", bound->to_string().c_str());
      log->info("listening on {}", bound->to_string());
    }
    std::printf("ready\n");
    std::fflush(stdout);
    notify("READY=1");

    asio::signal_set signals(net, SIGINT, SIGTERM);
    asio::steady_timer force_stop(net);
    std::function<void()> stop_poll;  // lives as long as the loop: the timer handler calls it
    signals.async_wait([&](const boost::system::error_code& ec, int sig) {
      if (ec) return;
      log->info("signal {}: shutting down", sig);
      notify("STOPPING=1");
      // Nothing new connects; the socket and its lock stay until the process is done, so no
      // second daemon starts on the path while this one still runs.
      server.stop_accepting();
      // No hot-plug step, no new device work; a batch that is running stops between frames, and
      // no more frames are handed to the network thread.
      hub.stop();
      const auto open = hub.shutdown_sessions();
      // Sessions close once their last reply is flushed; never wait longer than 1 s in total.
      const auto give_up = std::chrono::steady_clock::now() + std::chrono::milliseconds(open ? 1000 : 0);
      std::function<void()> poll = [&, give_up] {
        if (hub.session_count() == 0 || std::chrono::steady_clock::now() >= give_up) {
          net.stop();
          return;
        }
        force_stop.expires_after(std::chrono::milliseconds(5));
        force_stop.async_wait([&stop_poll](const boost::system::error_code&) { stop_poll(); });
      };
      stop_poll = std::move(poll);
      stop_poll();
    });
    net.run();
    // The device thread may still be inside a request (stopping at its next cancel point) or a
    // hot-plug step: let it finish before the hub it works on is destroyed.
    hub.stop();
    join_device();
    server.stop();  // socket and lock files removed, the lock released: now another daemon may start
  }
  log->info("stopped");
  return exit_code;
}

// `--check-config`: what the daemon would serve, in words (or JSON), and the effective
// configuration as a file --config accepts.
int print_checked_config(const daemon::DaemonConfig& cfg, const std::string& config_path, const std::string& backend,
                         bool json) {
  std::vector<std::string> listen;
  for (const auto& text : cfg.listen) listen.push_back(client::parse_address(text)->to_string());  // finalize parsed them
  const std::string token = cfg.token.empty()       ? "none"
                            : cfg.token_file.empty() ? "set (not shown)"
                                                     : "from " + cfg.token_file + " (not shown)";
  const auto effective = daemon::config_to_json(cfg);
  if (json) {
    const nlohmann::json out{{"ok", true},   {"config_file", config_path}, {"backend", backend},
                             {"listen", listen}, {"token", token},        {"config", effective}};
    std::printf("%s\n", json_text(out, 2).c_str());
    return 0;
  }
  std::printf("gpubridged: configuration OK (%s)\n", config_path.empty() ? "defaults and flags" : config_path.c_str());
  std::printf("  backend: %s\n", backend.c_str());
  for (const auto& l : listen) std::printf("  listen:  %s\n", l.c_str());
  std::printf("  token:   %s\n", token.c_str());
  std::printf("  tls_dir: %s\n", (cfg.tls_dir.empty() ? daemon::default_tls_dir() : cfg.tls_dir).c_str());
  std::printf("effective configuration (loadable with --config):\n%s\n", json_text(effective, 2).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"gpubridged: serves spigpu and DMC-1 devices (simulators or boards) to gpubridge clients over Unix/TCP sockets"};
  app.set_version_flag("--version", std::string("gpubridged ") + gpubridge::kVersion);
  std::string config_path;
  std::vector<std::string> listen;
  std::string token, token_file, backend, boards_dir, frames_dir, record_dir, log_level;
  std::optional<unsigned> max_clients, max_pending, handshake_ms, idle_ms, trickle_ms, min_rate;
  std::optional<std::uint32_t> max_message;
  std::optional<std::uint64_t> queue_bytes;
  std::optional<unsigned> reattach_ms;
  bool foreground = false;
  bool no_fallback = false;
  bool mirror = false;
  bool check_config = false, json = false;
  app.add_option("-c,--config", config_path, "JSON configuration file (see configs/gpubridged.json)");
  app.add_option("-l,--listen", listen, "unix:PATH or tcp:HOST:PORT (repeatable; replaces the config's list)");
  app.add_option("--token", token, "token TCP clients must present (required for non-loopback TCP)");
  app.add_option("--token-file", token_file, "read the token from the first line of this file");
  std::string tls_dir, dmc1_textures, dmc1_palette;
  bool print_fingerprint = false;
  app.add_option("--tls-dir", tls_dir, "directory of the TLS key and self-signed certificate (created on first start)");
  app.add_flag("--tls-fingerprint", print_fingerprint,
               "print the TLS certificate's fingerprint (creating the key if there is none) and exit; give it to "
               "clients as GPUBRIDGE_TLS_FINGERPRINT");
  app.add_option("-b,--backend", backend,
                 gpubridge::daemon::backend_syntax() +
                     " (BOARD: a board profile name or .json file, a spigpu board or a DMC-1 UART board such as "
                     "icebreaker-dmc1; dmc1: the DMC-1 simulator; presence: the emulated adapter is plugged in while "
                     "PATH exists; rtl: the board's gateware, Verilated, behind its bridge chip model)");
  app.add_option("--dmc1-textures", dmc1_textures,
                 "DMC-1 backends: the texture memory image (raw or .gz; default: the repository's tests/dmc1/data, "
                 "which its DMC-1 streams and goldens use)");
  app.add_option("--dmc1-palette", dmc1_palette, "DMC-1 backends: the palette (768 bytes; default: tests/dmc1/data's)");
  app.add_flag("--no-fallback", no_fallback, "do not switch to the simulator when a board disappears");
  std::vector<std::string> accuracy;
  app.add_option("--accuracy", accuracy,
                 "the simulator's accuracy: exact (default), preview (the float rasteriser: faster, not the hardware's "
                 "bits; docs/simulator.md) and/or knobs KNOB=VALUE; for backend sim, auto without a board and a board's "
                 "fallback (a --mirror model is always exact)")
      ->expected(1, 16);
  app.add_flag("--mirror", mirror,
               "board backends: also run the simulator on the same commands and compare every frame "
               "(subscribers may ask for the board, the simulator or a diff image)");
  app.add_option("--reattach-interval-ms", reattach_ms,
                 "board backends: probe the board and, after an unplug, look for it again this often; "
                 "auto without a board at start keeps looking for one at this interval "
                 "(default 1000; 0 = never re-attach)");
  app.add_option("--boards-dir", boards_dir, "directory of board profiles (JSON)");
  app.add_option("--frames-dir", frames_dir, "write every scanned-out frame as frame_NNNNNN.png here");
  app.add_option("--record", record_dir, "write each session's command stream as a binary trace here");
  app.add_option("--max-clients", max_clients, "clients served at once (1..4096; counted at HELLO)");
  app.add_option("--max-pending-handshakes", max_pending,
                 "connections per transport still waiting for their HELLO (1..4096; the oldest gives way)");
  app.add_option("--max-message", max_message, "largest accepted message payload in bytes");
  app.add_option("--handshake-timeout-ms", handshake_ms, "HELLO deadline");
  app.add_option("--idle-timeout-ms", idle_ms,
                 "close sessions silent this long, subscribers that answer no keepalive, and clients that take "
                 "nothing written to them (0 = never)");
  app.add_option("--trickle-window-ms", trickle_ms, "window of the minimum-byte-rate check");
  app.add_option("--min-bytes-per-sec", min_rate, "minimum rate while a message is incomplete");
  app.add_option("--queue-bytes", queue_bytes, "outgoing bytes queued per session before reading pauses");
  app.add_option("--log-level", log_level, gpubridge::log_levels_text())
      ->check(CLI::IsMember(std::vector<std::string>(gpubridge::kLogLevels.begin(), gpubridge::kLogLevels.end())));
  auto* check_flag = app.add_flag("--check-config", check_config,
                                  "check the configuration (file and flags) and the backend it names without opening any "
                                  "device, print the effective configuration and exit (0 valid, 2 not)");
  app.add_flag("--json", json, "with --check-config: the result as JSON on stdout")->needs(check_flag);
  app.add_flag("--foreground", foreground,
               "stay in the foreground (gpubridged never forks; run it under systemd or your shell's job control)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  // Configuration errors exit 2; with --check-config --json they are also reported on stdout.
  auto config_error = [&](const std::string& message) {
    if (check_config && json) std::printf("%s\n", gpubridge::json_text(nlohmann::json{{"ok", false}, {"error", message}}).c_str());
    std::fprintf(stderr, "gpubridged: %s\n", message.c_str());
    return 2;
  };
  gpubridge::daemon::DaemonConfig cfg;
  if (!config_path.empty()) {
    auto loaded = gpubridge::daemon::load_config(config_path);
    if (!loaded) return config_error(loaded.error().message);
    cfg = std::move(*loaded);
  }
  if (!listen.empty()) cfg.listen = listen;
  if (!token.empty()) cfg.token = token;
  if (!token_file.empty()) cfg.token_file = token_file;
  if (!backend.empty()) cfg.backend = backend;
  if (no_fallback) cfg.fallback_to_sim = false;
  if (mirror) cfg.mirror = true;
  if (reattach_ms) cfg.reattach_interval_ms = *reattach_ms;
  if (!boards_dir.empty()) cfg.boards_dir = boards_dir;
  if (!frames_dir.empty()) cfg.frames_dir = frames_dir;
  if (!record_dir.empty()) cfg.record_dir = record_dir;
  if (!log_level.empty()) cfg.log_level = log_level;
  if (!tls_dir.empty()) cfg.tls_dir = tls_dir;
  if (!accuracy.empty()) cfg.accuracy = accuracy;
  if (!dmc1_textures.empty()) cfg.dmc1_textures = dmc1_textures;
  if (!dmc1_palette.empty()) cfg.dmc1_palette = dmc1_palette;
  if (max_clients) cfg.limits.max_clients = *max_clients;
  if (max_pending) cfg.limits.max_pending_handshakes = *max_pending;
  if (max_message) cfg.limits.max_message_bytes = *max_message;
  if (handshake_ms) cfg.limits.handshake_timeout_ms = *handshake_ms;
  if (idle_ms) cfg.limits.idle_timeout_ms = *idle_ms;
  if (trickle_ms) cfg.limits.trickle_window_ms = *trickle_ms;
  if (min_rate) cfg.limits.min_bytes_per_sec = *min_rate;
  if (queue_bytes) cfg.limits.queue_bytes = *queue_bytes;
  if (auto r = gpubridge::daemon::finalize_config(cfg); !r) return config_error(r.error().message);
  if (auto r = gpubridge::daemon::check_output_dirs(cfg); !r) return config_error(r.error().message);
  if (print_fingerprint) {
    auto id = gpubridge::daemon::load_or_create_tls_identity(cfg.tls_dir.empty() ? gpubridge::daemon::default_tls_dir()
                                                                                 : cfg.tls_dir);
    if (!id) {
      std::fprintf(stderr, "gpubridged: %s\n", id.error().message.c_str());
      return 1;
    }
    std::printf("%s\n", id->fingerprint.c_str());
    return 0;
  }
  if (check_config) {
    auto backend_text = gpubridge::daemon::check_backend(cfg);
    if (!backend_text) return config_error(backend_text.error().message);
    return print_checked_config(cfg, config_path, *backend_text, json);
  }
  for (const auto& dir : {cfg.frames_dir, cfg.record_dir}) {
    std::error_code ec;
    if (!dir.empty()) std::filesystem::create_directories(dir, ec);
    if (ec) {
      std::fprintf(stderr, "gpubridged: cannot create %s: %s\n", dir.c_str(), ec.message().c_str());
      return 1;
    }
  }
  gpubridge::init_logging(cfg.log_level);
  (void)foreground;
  return run(std::move(cfg));
}
