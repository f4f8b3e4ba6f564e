#pragma once
// gpubridged configuration: a JSON file (configs/gpubridged.json) overridden by command-line flags.
// Every problem is reported as "<source>: <key.path>: <what is wrong>".
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "gpubridge/common/result.hpp"

namespace gpubridge::daemon {

struct Limits {
  std::uint32_t max_message_bytes = 16u << 20;  // largest accepted message payload (≤ protocol::kMaxPayload)
  unsigned max_clients = 64;                    // handshaken sessions beyond this get SERVER_FULL at HELLO
  unsigned max_pending_handshakes = 16;         // per transport: connections waiting for HELLO (oldest gives way)
  unsigned handshake_timeout_ms = 10000;        // HELLO must arrive within this
  unsigned idle_timeout_ms = 300000;            // no bytes at all (subscribers: no answer to a keepalive); 0 = off
  unsigned trickle_window_ms = 5000;            // an unfinished message must grow by ...
  unsigned min_bytes_per_sec = 256;             // ... at least this rate over each window
  std::uint64_t queue_bytes = 8ull << 20;       // replies queued per session before reading and dispatching pause
};

inline constexpr unsigned kMaxReattachIntervalMs = 3600000;  // one hour
inline constexpr std::uint64_t kMaxConfigFileBytes = 1u << 20;
inline constexpr std::uint64_t kMaxTokenFileBytes = 4096;

struct DaemonConfig {
  std::vector<std::string> listen;  // "unix:PATH" | "tcp:HOST:PORT" | "tls:HOST:PORT"; empty = the default Unix socket
  std::string token;                // required from TCP clients when set
  std::string token_file;           // alternative to token (first line, trimmed)
  std::string backend = "sim";      // "sim" | "discard" | "fake" | board name | "auto"
  bool fallback_to_sim = true;      // board lost → continue on the simulator
  bool mirror = false;              // board backends: run the simulator alongside and compare (docs/daemon.md)
  unsigned reattach_interval_ms = 1000;  // board lost → look for it again this often (0 = never);
                                        // also the interval of the presence probe while attached
  std::string boards_dir;           // board profiles (JSON)
  std::string frames_dir;           // write every scanned-out frame as PNG here
  std::string record_dir;           // write each session's stream as a binary trace here
  std::string log_level = "info";
  // DMC-1 backends (docs/dmc1.md "Behind the daemon"): the texture memory image and the palette;
  // empty = the data the repository's DMC-1 streams and goldens were made with (tests/dmc1/data).
  std::string dmc1_textures;
  std::string dmc1_palette;
  std::string tls_dir;              // TLS key + self-signed certificate (created on first start); empty = default_tls_dir()
  // The simulator's accuracy settings (`--accuracy preview`, knobs KNOB=VALUE; sim::apply_knob), for
  // every simulator this daemon serves: backend sim, auto without a board, a board's fallback. A
  // mirror's model is always exact (it is the reference the board is compared with).
  std::vector<std::string> accuracy;
  Limits limits;
};

// Parses a configuration document; `source` names it in error messages.
Result<DaemonConfig> parse_config(const nlohmann::json& doc, const std::string& source);
Result<DaemonConfig> load_config(const std::filesystem::path& path);
// The configuration as a document parse_config accepts: the effective settings after flags, for
// `gpubridged --check-config --json`. Secrets stay out: `token_file` is kept when the token came
// from one, a token given directly is left out.
nlohmann::json config_to_json(const DaemonConfig& cfg);
// frames_dir and record_dir: each unset, a writable directory, or creatable (its nearest existing
// ancestor is a writable directory). Checked at start and by --check-config, so a daemon that
// could not write its frames or recordings says so instead of logging a warning per frame.
Result<void> check_output_dirs(const DaemonConfig& cfg);
// Cross-field checks after flags were applied: addresses parse, non-loopback TCP has a token,
// limits (also those set by flags) are in range, token_file is read into token.
Result<void> finalize_config(DaemonConfig& cfg);

}  // namespace gpubridge::daemon
