#include "gpubridge/daemon/config.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <nlohmann/json.hpp>

#include "gpubridge/client/address.hpp"
#include "gpubridge/common/regular_file.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/common/try.hpp"
#include "gpubridge/protocol/messages.hpp"
#include "gpubridge/sim/options.hpp"

namespace gpubridge::daemon {
namespace {

using nlohmann::json;

class Reader {
 public:
  Reader(const std::string& source) : source_(source) {}

  Error fail(const std::string& key, const std::string& what) const {
    return make_error(source_ + ": " + key + ": " + what);
  }
  // Containers are named, not dumped: dump() recurses once per nesting level, so a deeply nested
  // value overflowed the stack while reporting its wrong type (a 200 KB input to fuzz_daemon_config).
  static std::string shown(const json& v) {
    if (v.is_array()) return "an array";
    if (v.is_object()) return "an object";
    std::string s = v.dump();
    if (s.size() <= 40) return s;
    // Cut at a character boundary: a UTF-8 continuation byte (10xxxxxx) never starts the tail.
    std::size_t cut = 37;
    while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
    return s.substr(0, cut) + "...";
  }

  Result<void> read_string(const json& obj, const std::string& prefix, const char* key, std::string& out) const {
    if (!obj.contains(key)) return {};
    const auto& v = obj.at(key);
    if (!v.is_string()) return fail(prefix + key, "expected a string, got " + shown(v));
    out = v.get<std::string>();
    return {};
  }
  Result<void> read_bool(const json& obj, const std::string& prefix, const char* key, bool& out) const {
    if (!obj.contains(key)) return {};
    const auto& v = obj.at(key);
    if (!v.is_boolean()) return fail(prefix + key, "expected true or false, got " + shown(v));
    out = v.get<bool>();
    return {};
  }
  template <class T>
  Result<void> read_uint(const json& obj, const std::string& prefix, const char* key, std::uint64_t lo, std::uint64_t hi,
                         T& out) const {
    if (!obj.contains(key)) return {};
    const auto& v = obj.at(key);
    const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<std::int64_t>() >= 0))
      return fail(prefix + key, "expected an integer " + range + ", got " + shown(v));
    const auto n = v.get<std::uint64_t>();
    if (n < lo || n > hi) return fail(prefix + key, "expected an integer " + range + ", got " + shown(v));
    out = static_cast<T>(n);
    return {};
  }
  Result<void> known_keys(const json& obj, const std::string& prefix, const std::vector<const char*>& keys) const {
    for (const auto& [k, v] : obj.items()) {
      bool found = false;
      for (const char* key : keys) found = found || k == key;
      if (!found) return fail(prefix + k, "unknown key (check the spelling; see docs/daemon.md)");
    }
    return {};
  }

 private:
  std::string source_;
};

// Every limit once: its config key, its flag and its range. parse_config checks the file's values
// against it and finalize_config checks the values flags set, so both report the same ranges.
template <class Limits_, class F>
void for_each_limit(Limits_& lim, F&& f) {
  f("max_message_bytes", "--max-message", protocol::kMinMaxPayload, protocol::kMaxPayload, lim.max_message_bytes);
  f("max_clients", "--max-clients", 1, 4096, lim.max_clients);
  f("max_pending_handshakes", "--max-pending-handshakes", 1, 4096, lim.max_pending_handshakes);
  f("handshake_timeout_ms", "--handshake-timeout-ms", 10, 600000, lim.handshake_timeout_ms);
  f("idle_timeout_ms", "--idle-timeout-ms", 0, 86400000, lim.idle_timeout_ms);
  f("trickle_window_ms", "--trickle-window-ms", 10, 600000, lim.trickle_window_ms);
  f("min_bytes_per_sec", "--min-bytes-per-sec", 0, 1u << 30, lim.min_bytes_per_sec);
  f("queue_bytes", "--queue-bytes", 1u << 20, 1ull << 32, lim.queue_bytes);
}

std::string log_level_problem(const std::string& level) {
  return "expected one of " + log_levels_text() + ", got " + Reader::shown(json(level));
}

}  // namespace

Result<DaemonConfig> parse_config(const json& doc, const std::string& source) {
  Reader rd(source);
  if (!doc.is_object()) return rd.fail("(top level)", "expected a JSON object");
  GPUBRIDGE_TRY(rd.known_keys(doc, "", {"listen", "token", "token_file", "backend", "fallback_to_sim", "reattach_interval_ms", "boards_dir",
                                        "frames_dir", "record_dir", "log_level", "limits", "mirror", "tls_dir", "dmc1_textures",
                                        "dmc1_palette", "accuracy", "comment"}));
  DaemonConfig cfg;
  if (doc.contains("listen")) {
    const auto& l = doc.at("listen");
    if (!l.is_array()) return rd.fail("listen", "expected an array of \"unix:PATH\" / \"tcp:HOST:PORT\" strings");
    for (std::size_t i = 0; i < l.size(); ++i) {
      const std::string key = "listen[" + std::to_string(i) + "]";
      if (!l[i].is_string()) return rd.fail(key, "expected a string, got " + Reader::shown(l[i]));
      auto a = client::parse_address(l[i].get<std::string>());
      if (!a) return rd.fail(key, a.error().message);
      cfg.listen.push_back(l[i].get<std::string>());
    }
  }
  GPUBRIDGE_TRY(rd.read_string(doc, "", "token", cfg.token));
  GPUBRIDGE_TRY(rd.read_string(doc, "", "token_file", cfg.token_file));
  GPUBRIDGE_TRY(rd.read_string(doc, "", "backend", cfg.backend));
  if (cfg.backend.empty()) return rd.fail("backend", "expected \"sim\", \"auto\", a board name, \"emulated:BOARD\" or \"rtl:BOARD\", got \"\"");
  GPUBRIDGE_TRY(rd.read_bool(doc, "", "fallback_to_sim", cfg.fallback_to_sim));
  GPUBRIDGE_TRY(rd.read_bool(doc, "", "mirror", cfg.mirror));
  GPUBRIDGE_TRY(rd.read_uint(doc, "", "reattach_interval_ms", 0, kMaxReattachIntervalMs, cfg.reattach_interval_ms));
  GPUBRIDGE_TRY(rd.read_string(doc, "", "boards_dir", cfg.boards_dir));
  GPUBRIDGE_TRY(rd.read_string(doc, "", "frames_dir", cfg.frames_dir));
  GPUBRIDGE_TRY(rd.read_string(doc, "", "record_dir", cfg.record_dir));
  GPUBRIDGE_TRY(rd.read_string(doc, "", "log_level", cfg.log_level));
  GPUBRIDGE_TRY(rd.read_string(doc, "", "tls_dir", cfg.tls_dir));
  GPUBRIDGE_TRY(rd.read_string(doc, "", "dmc1_textures", cfg.dmc1_textures));
  GPUBRIDGE_TRY(rd.read_string(doc, "", "dmc1_palette", cfg.dmc1_palette));
  if (doc.contains("accuracy")) {  // "preview", or a list of settings: ["preview", "z_bits=16"]
    const auto& a = doc.at("accuracy");
    if (a.is_string()) {
      cfg.accuracy = {a.get<std::string>()};
    } else if (a.is_array() && std::all_of(a.begin(), a.end(), [](const json& v) { return v.is_string(); })) {
      cfg.accuracy = a.get<std::vector<std::string>>();
    } else {
      return rd.fail("accuracy", "expected \"exact\", \"preview\" or an array of such settings and KNOB=VALUE strings, got " +
                                     Reader::shown(a));
    }
    if (auto k = sim::parse_knobs(cfg.accuracy); !k) return rd.fail("accuracy", k.error().message);
  }
  if (!is_log_level(cfg.log_level)) return rd.fail("log_level", log_level_problem(cfg.log_level));
  if (doc.contains("limits")) {
    const auto& l = doc.at("limits");
    if (!l.is_object()) return rd.fail("limits", "expected an object");
    std::vector<const char*> keys;
    for_each_limit(cfg.limits, [&](const char* key, const char*, std::uint64_t, std::uint64_t, auto&) { keys.push_back(key); });
    GPUBRIDGE_TRY(rd.known_keys(l, "limits.", keys));
    Result<void> bad;
    for_each_limit(cfg.limits, [&](const char* key, const char*, std::uint64_t lo, std::uint64_t hi, auto& value) {
      if (bad) bad = rd.read_uint(l, "limits.", key, lo, hi, value);
    });
    if (!bad) return bad.error();
  }
  return cfg;
}

nlohmann::json config_to_json(const DaemonConfig& cfg) {
  json doc{{"listen", cfg.listen},
           {"backend", cfg.backend},
           {"fallback_to_sim", cfg.fallback_to_sim},
           {"mirror", cfg.mirror},
           {"reattach_interval_ms", cfg.reattach_interval_ms},
           {"boards_dir", cfg.boards_dir},
           {"frames_dir", cfg.frames_dir},
           {"record_dir", cfg.record_dir},
           {"log_level", cfg.log_level}};
  if (!cfg.token_file.empty()) doc["token_file"] = cfg.token_file;
  if (!cfg.tls_dir.empty()) doc["tls_dir"] = cfg.tls_dir;
  if (!cfg.dmc1_textures.empty()) doc["dmc1_textures"] = cfg.dmc1_textures;
  if (!cfg.dmc1_palette.empty()) doc["dmc1_palette"] = cfg.dmc1_palette;
  if (!cfg.accuracy.empty()) doc["accuracy"] = cfg.accuracy;
  json limits = json::object();
  for_each_limit(cfg.limits, [&](const char* key, const char*, std::uint64_t, std::uint64_t, auto value) { limits[key] = value; });
  doc["limits"] = limits;
  return doc;
}

Result<void> check_output_dirs(const DaemonConfig& cfg) {
  const std::pair<const char*, const std::string*> dirs[] = {{"frames_dir", &cfg.frames_dir}, {"record_dir", &cfg.record_dir}};
  for (const auto& [key, value] : dirs) {
    if (value->empty()) continue;
    std::filesystem::path p = std::filesystem::absolute(*value);
    std::error_code ec;
    // The directory itself, or the nearest ancestor that exists (the daemon creates the rest).
    while (!std::filesystem::exists(p, ec) && p.has_parent_path() && p != p.parent_path()) p = p.parent_path();
    if (!std::filesystem::is_directory(p, ec))
      return make_error(std::string(key) + ": " + *value + ": " + p.string() + " is not a directory");
    if (::access(p.c_str(), W_OK | X_OK) != 0)
      return make_error(std::string(key) + ": " + *value + ": " + p.string() + " is not writable by this user (" +
                        std::strerror(errno) + "); choose another directory or fix its permissions");
  }
  return {};
}

Result<DaemonConfig> load_config(const std::filesystem::path& path) {
  // A directory, FIFO or device is refused by what it is, without blocking or reading 2 GB.
  auto text = read_regular_file(path, kMaxConfigFileBytes, "configuration file");
  if (!text) return text.error();
  json doc;
  try {
    doc = json::parse(*text, nullptr, true, /*ignore_comments=*/true);
  } catch (const json::exception& e) {  // parse_error, or out_of_range for a number beyond double (1e999)
    return make_error(path.string() + ": not valid JSON: " + e.what());
  }
  return parse_config(doc, path.string());
}

Result<void> finalize_config(DaemonConfig& cfg) {
  if (!cfg.token_file.empty()) {
    auto text = read_regular_file(cfg.token_file, kMaxTokenFileBytes, "token file");
    if (!text) return make_error("token_file: " + text.error().message);
    std::string line = text->substr(0, text->find('\n'));
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
    if (line.empty()) return make_error("token_file: " + cfg.token_file + " is empty (expected the token on its first line)");
    cfg.token = line;
  }
  if (cfg.token.size() > protocol::kMaxTokenBytes)
    return make_error("token: longer than " + std::to_string(protocol::kMaxTokenBytes) + " bytes");
  if (cfg.listen.empty()) cfg.listen.push_back("unix:");
  for (const auto& text : cfg.listen) {
    auto a = client::parse_address(text);
    if (!a) return make_error("listen: " + a.error().message);
    if (a->kind == client::Address::Kind::Tcp && !client::is_loopback_host(a->host) && cfg.token.empty())
      return make_error("listen: " + a->to_string() +
                        " is reachable from other machines; set a token (\"token\" / \"token_file\" or --token) "
                        "or bind 127.0.0.1");
  }
  Result<void> bad;
  for_each_limit(cfg.limits, [&](const char* key, const char* flag, std::uint64_t lo, std::uint64_t hi, auto value) {
    const auto v = static_cast<std::uint64_t>(value);
    if (bad && (v < lo || v > hi))
      bad = make_error("limits." + std::string(key) + " (" + flag + "): expected an integer " + std::to_string(lo) +
                       ".." + std::to_string(hi) + ", got " + std::to_string(v));
  });
  if (!bad) return bad;
  if (!is_log_level(cfg.log_level)) return make_error("log_level (--log-level): " + log_level_problem(cfg.log_level));
  auto knobs = sim::parse_knobs(cfg.accuracy);
  if (!knobs) return make_error("accuracy (--accuracy): " + knobs.error().message);
  sim::DeviceOptions with_knobs;
  with_knobs.accuracy = *knobs;
  if (auto v = with_knobs.validate(); !v) return make_error("accuracy (--accuracy): " + v.error().message);
  if (cfg.reattach_interval_ms > kMaxReattachIntervalMs)
    return make_error("reattach_interval_ms: expected 0.." + std::to_string(kMaxReattachIntervalMs) + " (0 = never), got " +
                      std::to_string(cfg.reattach_interval_ms));
  return {};
}

}  // namespace gpubridge::daemon
