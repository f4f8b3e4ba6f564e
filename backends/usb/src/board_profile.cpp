#include "gpubridge/usb/board_profile.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "gpubridge/backends/backend.hpp"

namespace gpubridge::usb {
namespace {

using nlohmann::json;

constexpr std::size_t kMaxProfileBytes = 1 << 20;

// Reads typed values out of a JSON object, naming file and key in every error.
class Reader {
 public:
  Reader(const json& obj, std::string file, std::string prefix)
      : obj_(obj), file_(std::move(file)), prefix_(std::move(prefix)) {}

  Error fail(const std::string& key, const std::string& what) const {
    return make_error(file_ + ": " + prefix_ + key + ": " + what, backends::kBadRequest);
  }
  const json* get(const std::string& key) {
    seen_.insert(key);
    auto it = obj_.find(key);
    return it == obj_.end() ? nullptr : &*it;
  }
  Result<std::string> str(const std::string& key, std::optional<std::string> dflt = std::nullopt) {
    const json* v = get(key);
    if (!v) {
      if (dflt) return *dflt;
      return fail(key, "missing (required string)");
    }
    if (!v->is_string()) return fail(key, "expected a string");
    return v->get<std::string>();
  }
  Result<std::uint64_t> uint(const std::string& key, std::uint64_t lo, std::uint64_t hi, std::optional<std::uint64_t> dflt = std::nullopt) {
    const json* v = get(key);
    if (!v) {
      if (dflt) return *dflt;
      return fail(key, "missing (required integer " + std::to_string(lo) + ".." + std::to_string(hi) + ")");
    }
    if (!v->is_number_unsigned() && !(v->is_number_integer() && v->get<std::int64_t>() >= 0))
      return fail(key, "expected a non-negative integer");
    const auto x = v->get<std::uint64_t>();
    if (x < lo || x > hi) return fail(key, std::to_string(x) + " is out of range " + std::to_string(lo) + ".." + std::to_string(hi));
    return x;
  }
  Result<std::uint16_t> hex16(const std::string& key) {
    auto s = str(key);
    if (!s) return s.error();
    std::string t = *s;
    if (t.rfind("0x", 0) == 0 || t.rfind("0X", 0) == 0) t = t.substr(2);
    if (t.empty() || t.size() > 4 || t.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
      return fail(key, "expected a 16-bit hex ID like \"0x0403\", got \"" + *s + "\"");
    return static_cast<std::uint16_t>(std::stoul(t, nullptr, 16));
  }
  Result<bool> boolean(const std::string& key, bool dflt) {
    const json* v = get(key);
    if (!v) return dflt;
    if (!v->is_boolean()) return fail(key, "expected true or false");
    return v->get<bool>();
  }
  Result<void> no_unknown_keys() const {
    for (auto it = obj_.begin(); it != obj_.end(); ++it)
      if (!seen_.count(it.key())) return fail(it.key(), "unknown key (typo?)");
    return {};
  }

 private:
  const json& obj_;
  std::string file_, prefix_;
  std::set<std::string> seen_;
};

Result<json> parse_json_file(const std::filesystem::path& file, std::string& text) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  if (ec) return make_error(file.string() + ": cannot read: " + ec.message(), backends::kBadRequest);
  if (size > kMaxProfileBytes) return make_error(file.string() + ": larger than 1 MiB; not a board profile", backends::kBadRequest);
  std::ifstream in(file, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  text = ss.str();
  return json::object();
}

std::uint32_t max_clock(BridgeChip c) {
  switch (c) {
    case BridgeChip::FT232H: case BridgeChip::FT2232H: case BridgeChip::FT4232H: return 30'000'000;
    case BridgeChip::CH341A: return 1'700'000;
    case BridgeChip::MCP2210: return 12'000'000;
    case BridgeChip::CP2130: return 12'000'000;
  }
  return 0;
}

}  // namespace

std::string_view to_string(BridgeChip c) {
  switch (c) {
    case BridgeChip::FT232H: return "ft232h";
    case BridgeChip::FT2232H: return "ft2232h";
    case BridgeChip::FT4232H: return "ft4232h";
    case BridgeChip::CH341A: return "ch341a";
    case BridgeChip::MCP2210: return "mcp2210";
    case BridgeChip::CP2130: return "cp2130";
  }
  return "?";
}

std::optional<BridgeChip> parse_bridge_chip(std::string_view s) {
  for (auto c : {BridgeChip::FT232H, BridgeChip::FT2232H, BridgeChip::FT4232H, BridgeChip::CH341A, BridgeChip::MCP2210,
                 BridgeChip::CP2130})
    if (to_string(c) == s) return c;
  return std::nullopt;
}

std::filesystem::path default_config_dir() {
  if (const char* env = std::getenv("GPUBRIDGE_CONFIG_DIR"); env && *env) return env;
  return GPUBRIDGE_DEFAULT_CONFIG_DIR;
}

Result<BoardProfile> parse_board_profile(std::string_view text, const std::string& file) {
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {  // parse_error, or out_of_range for a number beyond double (1e999)
    return make_error(file + ": not valid JSON: " + e.what(), backends::kBadRequest);
  }
  if (!root.is_object()) return make_error(file + ": expected a JSON object at the top level", backends::kBadRequest);
  BoardProfile p;
  p.file = file;
  Reader top(root, file, "");
#define TRY_SET(dst, expr)          \
  {                                 \
    auto r_ = (expr);               \
    if (!r_) return r_.error();     \
    dst = *r_;                      \
  }
  TRY_SET(p.name, top.str("name"));
  if (p.name.empty() || p.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") != std::string::npos)
    return top.fail("name", "use lower-case letters, digits, '-' and '_' only");
  TRY_SET(p.description, top.str("description", ""));
  TRY_SET(p.fpga, top.str("fpga", ""));
  std::string scanout;
  TRY_SET(scanout, top.str("scanout", "readback"));
  if (scanout == "readback") p.scanout = ScanoutMode::Readback;
  else if (scanout == "crc") p.scanout = ScanoutMode::CrcOnly;
  else if (scanout == "off") p.scanout = ScanoutMode::Off;
  else return top.fail("scanout", "expected \"readback\", \"crc\" or \"off\"");

  const json* bridge = top.get("bridge");
  if (!bridge || !bridge->is_object()) return top.fail("bridge", "missing (required object)");
  Reader b(*bridge, file, "bridge.");
  std::string chip;
  TRY_SET(chip, b.str("chip"));
  const auto c = parse_bridge_chip(chip);
  if (!c) return b.fail("chip", "unknown chip \"" + chip + "\" (ft232h, ft2232h, ft4232h, ch341a, mcp2210, cp2130)");
  p.chip = *c;
  TRY_SET(p.vid, b.hex16("vid"));
  TRY_SET(p.pid, b.hex16("pid"));
  std::string iface;
  TRY_SET(iface, b.str("interface", "A"));
  if (iface == "A") p.interface = 0;
  else if (iface == "B") p.interface = 1;
  else return b.fail("interface", "expected \"A\" or \"B\"");
  if (p.interface == 1 && (p.chip != BridgeChip::FT2232H && p.chip != BridgeChip::FT4232H))
    return b.fail("interface", "only FT2232H/FT4232H have a second MPSSE channel");
  TRY_SET(p.serial, b.str("serial", ""));
  TRY_SET(p.port_path, b.str("port_path", ""));
  TRY_SET(p.spi_clock_hz, b.uint("spi_clock_hz", 1000, max_clock(p.chip)));
  TRY_SET(p.cs_pin, b.uint("cs_pin", 0, 10, 3));
  TRY_SET(p.busy_pin, b.boolean("busy_pin", false));
  if (p.busy_pin && p.chip != BridgeChip::FT232H && p.chip != BridgeChip::FT2232H && p.chip != BridgeChip::FT4232H)
    return b.fail("busy_pin", "only FTDI MPSSE can wait on a BUSY pin (wait-on-I/O); set false");
  if ((p.chip == BridgeChip::FT232H || p.chip == BridgeChip::FT2232H || p.chip == BridgeChip::FT4232H) &&
      (p.cs_pin < 3 || p.cs_pin > 7 || (p.busy_pin && p.cs_pin == 5)))
    return b.fail("cs_pin", "FTDI chip select must be ADBUS3..7 (and not 5, GPIOL1, when busy_pin is wired)");
  std::string edge;
  TRY_SET(edge, b.str("read_edge", "rising"));
  if (edge == "rising") p.read_edge = ReadEdge::Rising;
  else if (edge == "falling") p.read_edge = ReadEdge::Falling;
  else return b.fail("read_edge", "expected \"rising\" or \"falling\"");
  TRY_SET(p.latency_ms, b.uint("latency_ms", 1, 255, 1));
  const bool ftdi = p.chip == BridgeChip::FT232H || p.chip == BridgeChip::FT2232H || p.chip == BridgeChip::FT4232H;
  if (!ftdi && b.get("stream_reads")) return b.fail("stream_reads", "only FTDI MPSSE streams reads; remove the key for this chip");
  TRY_SET(p.stream_reads, b.boolean("stream_reads", true));
  if (auto r = b.no_unknown_keys(); !r) return r.error();

  const json* dev = top.get("device");
  if (!dev || !dev->is_object()) return top.fail("device", "missing (required object)");
  Reader d(*dev, file, "device.");
  TRY_SET(p.vram_kib, d.uint("vram_kib", 1, 0xFFFFFF));
  TRY_SET(p.max_width, d.uint("max_width", 1, protocol::kMaxFramebufferDim));
  TRY_SET(p.max_height, d.uint("max_height", 1, protocol::kMaxFramebufferDim));
  TRY_SET(p.fifo_depth, d.uint("fifo_depth", 33, 1023));
  TRY_SET(p.clock_mhz, d.uint("clock_mhz", 1, 1000, 50));
  if (auto r = d.no_unknown_keys(); !r) return r.error();

  if (const json* link = top.get("link")) {
    if (!link->is_object()) return top.fail("link", "expected an object");
    Reader l(*link, file, "link.");
    TRY_SET(p.strict_link, l.boolean("strict", true));
    if (auto r = l.no_unknown_keys(); !r) return r.error();
  }
#undef TRY_SET
  if (auto r = top.no_unknown_keys(); !r) return r.error();
  return p;
}

Result<BoardProfile> load_board_profile(const std::filesystem::path& file) {
  std::string text;
  if (auto r = parse_json_file(file, text); !r) return r.error();
  return parse_board_profile(text, file.string());
}

Result<std::vector<BoardProfile>> load_board_profiles(const std::filesystem::path& config_dir) {
  const auto dir = config_dir / "boards";
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    return make_error(dir.string() + ": no board profile directory (set GPUBRIDGE_CONFIG_DIR or --config-dir)", backends::kBadRequest);
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::vector<BoardProfile> out;
  for (const auto& f : files) {
    auto p = load_board_profile(f);
    if (!p) return p.error();
    out.push_back(std::move(*p));
  }
  return out;
}

Result<BoardProfile> find_board_profile(const std::filesystem::path& config_dir, const std::string& name) {
  if (name.size() > 5 && name.ends_with(".json")) return load_board_profile(name);
  auto all = load_board_profiles(config_dir);
  if (!all) return all.error();
  std::string names;
  for (auto& p : *all) {
    if (p.name == name) return std::move(p);
    names += (names.empty() ? "" : ", ") + p.name;
  }
  return make_error("no board profile named \"" + name + "\" in " + (config_dir / "boards").string() + " (known: " + names + ")",
                    backends::kBadRequest);
}

Result<std::vector<CableInfo>> load_cables(const std::filesystem::path& config_dir) {
  const auto dir = config_dir / "cables";
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return make_error(dir.string() + ": no cable directory", backends::kBadRequest);
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::vector<CableInfo> out;
  for (const auto& f : files) {
    std::string text;
    if (auto r = parse_json_file(f, text); !r) return r.error();
    json root;
    try {
      root = json::parse(text);
    } catch (const json::exception& e) {  // parse_error, or out_of_range for a number beyond double (1e999)
      return make_error(f.string() + ": not valid JSON: " + e.what(), backends::kBadRequest);
    }
    if (!root.is_object()) return make_error(f.string() + ": expected a JSON object", backends::kBadRequest);
    Reader r(root, f.string(), "");
    CableInfo c;
    c.file = f;
#define TRY_SET(dst, expr)      \
  {                             \
    auto r_ = (expr);           \
    if (!r_) return r_.error(); \
    dst = *r_;                  \
  }
    TRY_SET(c.name, r.str("name"));
    TRY_SET(c.chip, r.str("chip"));
    if (!parse_bridge_chip(c.chip)) return r.fail("chip", "unknown chip \"" + c.chip + "\"");
    TRY_SET(c.description, r.str("description", ""));
    TRY_SET(c.api, r.str("api"));
    TRY_SET(c.vid, r.hex16("vid"));
    TRY_SET(c.pid, r.hex16("pid"));
    TRY_SET(c.max_spi_hz, r.uint("max_spi_hz", 1000, 100'000'000));
#undef TRY_SET
    if (const json* ifs = r.get("interfaces")) {
      if (!ifs->is_array()) return r.fail("interfaces", "expected an array of strings");
      for (const auto& i : *ifs) {
        if (!i.is_string()) return r.fail("interfaces", "expected an array of strings");
        c.interfaces.push_back(i.get<std::string>());
      }
    }
    if (auto u = r.no_unknown_keys(); !u) return u.error();
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace gpubridge::usb
