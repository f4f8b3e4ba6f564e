#include "gpubridge/usb/board_profile.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/common/try.hpp"

namespace gpubridge::usb {
namespace {

using nlohmann::json;

constexpr std::size_t kMaxConfigBytes = 1 << 20;

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
  // A finite number in [lo, hi] (JSON has no NaN or Inf, but 1e999 parses as Inf in some readers).
  Result<double> number(const std::string& key, double lo, double hi, double dflt) {
    const json* v = get(key);
    if (!v) return dflt;
    if (!v->is_number()) return fail(key, "expected a number");
    const auto x = v->get<double>();
    if (!std::isfinite(x) || x < lo || x > hi)
      return fail(key, v->dump() + " is out of range " + json(lo).dump() + ".." + json(hi).dump());
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
  Result<const BridgeChipInfo*> chip(const std::string& key) {
    auto name = str(key);
    if (!name) return name.error();
    if (const auto* c = find_chip(*name)) return c;
    return fail(key, "unknown chip \"" + *name + "\" (" + chip_names() + ")");
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

Result<std::string> read_config_file(const std::filesystem::path& file) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  if (ec) return make_error(file.string() + ": cannot read: " + ec.message(), backends::kBadRequest);
  if (size > kMaxConfigBytes) return make_error(file.string() + ": larger than 1 MiB; not a board profile", backends::kBadRequest);
  std::ifstream in(file, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

Result<json> parse_json_object(std::string_view text, const std::string& file) {
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {  // parse_error, or out_of_range for a number beyond double (1e999)
    return make_error(file + ": not valid JSON: " + e.what(), backends::kBadRequest);
  }
  if (!root.is_object()) return make_error(file + ": expected a JSON object at the top level", backends::kBadRequest);
  return root;
}

// A board file's "device_kind" (default spigpu), which says whether the SPI or the UART board loader reads it.
Result<protocol::DeviceKind> device_kind_of(const json& root, const std::string& file) {
  const auto it = root.find("device_kind");
  if (it == root.end()) return protocol::DeviceKind::Spigpu;
  if (!it->is_string()) return make_error(file + ": device_kind: expected a string (" + protocol::device_kind_names() + ")", backends::kBadRequest);
  const auto name = it->get<std::string>();
  if (auto k = protocol::parse_device_kind(name)) return *k;
  return make_error(file + ": device_kind: unknown \"" + name + "\" (" + protocol::device_kind_names() + ")", backends::kBadRequest);
}

// Whether a board file is read by the SPI-board loader (spigpu) or the UART-board loader (the rest).
enum class BoardFamily { Spi, Uart };
Result<bool> board_file_is(BoardFamily family, std::string_view text, const std::string& file) {
  auto root = parse_json_object(text, file);
  if (!root) return root.error();
  auto kind = device_kind_of(*root, file);
  if (!kind) return kind.error();
  return (*kind == protocol::DeviceKind::Spigpu) == (family == BoardFamily::Spi);
}
Result<bool> spi_board_file(std::string_view text, const std::string& file) { return board_file_is(BoardFamily::Spi, text, file); }
Result<bool> uart_board_file(std::string_view text, const std::string& file) { return board_file_is(BoardFamily::Uart, text, file); }

// Every *.json file of `dir`, in name order, through `parse` (those `wanted` accepts, when given);
// the first bad file is the error.
template <class T>
Result<std::vector<T>> load_dir(const std::filesystem::path& dir, const std::string& what_is_missing,
                                Result<T> (*parse)(std::string_view text, const std::string& file),
                                Result<bool> (*wanted)(std::string_view text, const std::string& file) = nullptr) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return make_error(dir.string() + ": " + what_is_missing, backends::kBadRequest);
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::vector<T> out;
  for (const auto& f : files) {
    auto text = read_config_file(f);
    if (!text) return text.error();
    if (wanted) {
      auto w = wanted(*text, f.string());
      if (!w) return w.error();
      if (!*w) continue;
    }
    auto item = parse(*text, f.string());
    if (!item) return item.error();
    out.push_back(std::move(*item));
  }
  return out;
}

// Cables are the chip table's entries as `gpubridge probe` looks for them; a file may name other
// USB ids (an adapter with its own PID) but not another transport, a faster clock or interfaces
// the chip lacks.
Result<CableInfo> parse_cable(std::string_view text, const std::string& file) {
  auto root = parse_json_object(text, file);
  if (!root) return root.error();
  Reader r(*root, file, "");
  CableInfo c;
  c.file = file;
  const BridgeChipInfo* chip = nullptr;
  GPUBRIDGE_TRY_SET(c.name, r.str("name"));
  GPUBRIDGE_TRY_SET(chip, r.chip("chip"));
  c.chip = std::string(chip->name);
  GPUBRIDGE_TRY_SET(c.description, r.str("description", ""));
  GPUBRIDGE_TRY_SET(c.api, r.str("api"));
  if (c.api != to_string(chip->api))
    return r.fail("api", "the " + std::string(chip->label) + " is reached through " + std::string(to_string(chip->api)));
  GPUBRIDGE_TRY_SET(c.vid, r.hex16("vid"));
  GPUBRIDGE_TRY_SET(c.pid, r.hex16("pid"));
  GPUBRIDGE_TRY_SET(c.max_spi_hz, r.uint("max_spi_hz", 1000, chip->max_clock_hz));
  if (const json* ifs = r.get("interfaces")) {
    if (!ifs->is_array()) return r.fail("interfaces", "expected an array of strings");
    for (const auto& i : *ifs) {
      if (!i.is_string()) return r.fail("interfaces", "expected an array of strings");
      c.interfaces.push_back(i.get<std::string>());
    }
    if (c.interfaces.size() > chip->channels)
      return r.fail("interfaces", "the " + std::string(chip->label) + " has " + std::to_string(chip->channels) +
                                      " SPI-capable interface" + (chip->channels == 1 ? "" : "s") + ", not " +
                                      std::to_string(c.interfaces.size()));
  }
  if (auto u = r.no_unknown_keys(); !u) return u.error();
  return c;
}

// What every board file starts with, whatever its kind: device_kind (read by the caller), name,
// description, fpga.
template <class Profile>
Result<void> read_identity(Reader& top, Profile& p) {
  top.get("device_kind");
  GPUBRIDGE_TRY_SET(p.name, top.str("name"));
  if (p.name.empty() || p.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") != std::string::npos)
    return top.fail("name", "use lower-case letters, digits, '-' and '_' only");
  GPUBRIDGE_TRY_SET(p.description, top.str("description", ""));
  GPUBRIDGE_TRY_SET(p.fpga, top.str("fpga", ""));
  return {};
}

// The optional "flash" section: the bitstream file the gateware build writes and the programmers
// that can load it; checked against the profile's "fpga" (iceprog programs iCE40 parts only).
template <class Profile>
Result<void> read_flash(Reader& top, const std::string& file, Profile& p) {
  const json* f = top.get("flash");
  if (!f) return {};
  if (!f->is_object()) return top.fail("flash", "expected an object (bitstream, openfpgaloader_board, iceprog, source)");
  const auto family = fpga_family(p.fpga);
  if (!family) return top.fail("flash", "needs \"fpga\" to name the part (\"iCE40 ...\" or \"ECP5 ...\"), got \"" + p.fpga + "\"");
  Reader r(*f, file, "flash.");
  auto& fl = p.flash;
  fl.present = true;
  GPUBRIDGE_TRY_SET(fl.bitstream, r.str("bitstream", ""));
  if (fl.bitstream.find('/') != std::string::npos || fl.bitstream == "." || fl.bitstream == "..")
    return r.fail("bitstream", "a file name in the bitstream directory, not a path");
  const std::string ext = *family == FpgaFamily::Ice40 ? ".bin" : ".bit";
  if (!fl.bitstream.empty() && !fl.bitstream.ends_with(ext))
    return r.fail("bitstream", "an " + std::string(*family == FpgaFamily::Ice40 ? "iCE40" : "ECP5") + " bitstream ends in " + ext);
  GPUBRIDGE_TRY_SET(fl.openfpgaloader_board, r.str("openfpgaloader_board", ""));
  GPUBRIDGE_TRY_SET(fl.iceprog, r.boolean("iceprog", false));
  if (fl.iceprog && *family != FpgaFamily::Ice40) return r.fail("iceprog", "iceprog programs iCE40 parts only");
  GPUBRIDGE_TRY_SET(fl.source, r.str("source", ""));
  if (fl.bitstream.empty() && fl.source.empty())
    return r.fail("source", "say where the bitstream comes from when this project does not build one (no \"bitstream\")");
  if (fl.openfpgaloader_board.empty() && !fl.iceprog) return r.fail("openfpgaloader_board", "missing: name a programmer (or \"iceprog\": true)");
  return r.no_unknown_keys();
}

// The profile called `name`, else nullptr with every name listed in `names`.
template <class Profile>
Profile* find_named(std::vector<Profile>& all, const std::string& name, std::string& names) {
  for (auto& p : all) {
    if (p.name == name) return &p;
    names += (names.empty() ? "" : ", ") + p.name;
  }
  return nullptr;
}

}  // namespace

std::filesystem::path default_config_dir() {
  if (const char* env = std::getenv("GPUBRIDGE_CONFIG_DIR"); env && *env) return env;
  return GPUBRIDGE_DEFAULT_CONFIG_DIR;
}

Result<BoardProfile> parse_board_profile(std::string_view text, const std::string& file) {
  auto root = parse_json_object(text, file);
  if (!root) return root.error();
  BoardProfile p;
  p.file = file;
  Reader top(*root, file, "");
  if (auto kind = device_kind_of(*root, file); !kind) {
    return kind.error();
  } else if (*kind != protocol::DeviceKind::Spigpu) {
    return top.fail("device_kind", "this is a " + std::string(protocol::device_kind_info(*kind).label) +
                                       " board, reached over its UART, not an SPI bridge: use it with `gpubridge render "
                                       "--device " + std::string(protocol::device_kind_info(*kind).name) + " --board NAME` (docs/dmc1.md)");
  }
  if (auto r = read_identity(top, p); !r) return r.error();
  std::string scanout;
  GPUBRIDGE_TRY_SET(scanout, top.str("scanout", "readback"));
  if (scanout == "readback") p.scanout = ScanoutMode::Readback;
  else if (scanout == "crc") p.scanout = ScanoutMode::CrcOnly;
  else if (scanout == "off") p.scanout = ScanoutMode::Off;
  else return top.fail("scanout", "expected \"readback\", \"crc\" or \"off\"");

  // The bridge: what the profile may ask of it is the chip table's row.
  const json* bridge = top.get("bridge");
  if (!bridge || !bridge->is_object()) return top.fail("bridge", "missing (required object)");
  Reader b(*bridge, file, "bridge.");
  const BridgeChipInfo* chip = nullptr;
  GPUBRIDGE_TRY_SET(chip, b.chip("chip"));
  p.chip = chip->chip;
  GPUBRIDGE_TRY_SET(p.vid, b.hex16("vid"));
  GPUBRIDGE_TRY_SET(p.pid, b.hex16("pid"));
  std::string iface;
  GPUBRIDGE_TRY_SET(iface, b.str("interface", "A"));
  if (iface == "A") p.interface = 0;
  else if (iface == "B") p.interface = 1;
  else return b.fail("interface", "expected \"A\" or \"B\"");
  if (p.interface >= static_cast<int>(chip->channels)) {
    std::string dual;
    for (const auto& c : bridge_chips())
      if (c.channels > 1) dual += (dual.empty() ? "" : "/") + std::string(c.label);
    return b.fail("interface", "only " + dual + " have a second MPSSE channel");
  }
  GPUBRIDGE_TRY_SET(p.serial, b.str("serial", ""));
  GPUBRIDGE_TRY_SET(p.port_path, b.str("port_path", ""));
  GPUBRIDGE_TRY_SET(p.spi_clock_hz, b.uint("spi_clock_hz", 1000, chip->max_clock_hz));
  GPUBRIDGE_TRY_SET(p.cs_pin, b.uint("cs_pin", 0, 10, 3));
  GPUBRIDGE_TRY_SET(p.busy_pin, b.boolean("busy_pin", false));
  if (p.busy_pin && chip->busy_gpio < 0)
    return b.fail("busy_pin", "only FTDI MPSSE can wait on a BUSY pin (wait-on-I/O); set false");
  if (p.cs_pin < chip->cs_min || p.cs_pin > chip->cs_max || (p.busy_pin && p.cs_pin == chip->busy_gpio))
    return b.fail("cs_pin", std::string(chip->cs_rule));
  std::string edge;
  GPUBRIDGE_TRY_SET(edge, b.str("read_edge", "rising"));
  if (edge == "rising") p.read_edge = ReadEdge::Rising;
  else if (edge == "falling") p.read_edge = ReadEdge::Falling;
  else return b.fail("read_edge", "expected \"rising\" or \"falling\"");
  GPUBRIDGE_TRY_SET(p.latency_ms, b.uint("latency_ms", 1, 255, 1));
  if (!chip->stream_reads && b.get("stream_reads"))
    return b.fail("stream_reads", "only FTDI MPSSE streams reads; remove the key for this chip");
  GPUBRIDGE_TRY_SET(p.stream_reads, b.boolean("stream_reads", true));
  if (auto r = b.no_unknown_keys(); !r) return r.error();

  const json* dev = top.get("device");
  if (!dev || !dev->is_object()) return top.fail("device", "missing (required object)");
  Reader d(*dev, file, "device.");
  GPUBRIDGE_TRY_SET(p.vram_kib, d.uint("vram_kib", 1, 0xFFFFFF));
  GPUBRIDGE_TRY_SET(p.max_width, d.uint("max_width", 1, protocol::kMaxFramebufferDim));
  GPUBRIDGE_TRY_SET(p.max_height, d.uint("max_height", 1, protocol::kMaxFramebufferDim));
  GPUBRIDGE_TRY_SET(p.fifo_depth, d.uint("fifo_depth", 33, 1023));
  GPUBRIDGE_TRY_SET(p.clock_mhz, d.number("clock_mhz", 1, 1000, 50));
  if (auto r = d.no_unknown_keys(); !r) return r.error();

  if (const json* link = top.get("link")) {
    if (!link->is_object()) return top.fail("link", "expected an object");
    Reader l(*link, file, "link.");
    GPUBRIDGE_TRY_SET(p.strict_link, l.boolean("strict", true));
    if (auto r = l.no_unknown_keys(); !r) return r.error();
  }
  if (const json* gw = top.get("gateware")) {
    if (!gw->is_object()) return top.fail("gateware", "expected an object");
    Reader g(*gw, file, "gateware.");
    GPUBRIDGE_TRY_SET(p.gateware, g.str("profile"));
    if (p.gateware != "up5k" && p.gateware != "ecp5") return g.fail("profile", "expected \"up5k\" or \"ecp5\"");
    GPUBRIDGE_TRY_SET(p.miso_delay_ns, g.uint("miso_delay_ns", 0, 1000, 20));
    if (auto r = g.no_unknown_keys(); !r) return r.error();
  }
  if (auto r = read_flash(top, file, p); !r) return r.error();
  if (auto r = top.no_unknown_keys(); !r) return r.error();
  return p;
}

Result<BoardProfile> load_board_profile(const std::filesystem::path& file) {
  auto text = read_config_file(file);
  if (!text) return text.error();
  return parse_board_profile(*text, file.string());
}

Result<std::vector<BoardProfile>> load_board_profiles(const std::filesystem::path& config_dir) {
  return load_dir<BoardProfile>(config_dir / "boards", "no board profile directory (set GPUBRIDGE_CONFIG_DIR or --config-dir)",
                                &parse_board_profile, &spi_board_file);
}

Result<BoardProfile> find_board_profile(const std::filesystem::path& config_dir, const std::string& name) {
  if (name.size() > 5 && name.ends_with(".json")) return load_board_profile(name);
  auto all = load_board_profiles(config_dir);
  if (!all) return all.error();
  std::string names;
  if (auto* p = find_named(*all, name, names)) return std::move(*p);
  std::string uart_names;
  if (auto uart = load_uart_board_profiles(config_dir))
    if (const auto* u = find_named(*uart, name, uart_names))
      return make_error("board \"" + name + "\" (" + u->file.string() + ") is a " +
                            std::string(protocol::device_kind_info(u->device_kind).label) +
                            " board on a USB-UART, not an spigpu board on an SPI bridge: stream to it with `gpubridge render --device " +
                            std::string(protocol::device_kind_info(u->device_kind).name) + " STREAM --board " + name + " ...` (docs/dmc1.md)",
                        backends::kBadRequest);
  return make_error("no board profile named \"" + name + "\" in " + (config_dir / "boards").string() + " (known: " + names + ")",
                    backends::kBadRequest);
}

Result<UartBoardProfile> parse_uart_board_profile(std::string_view text, const std::string& file) {
  auto root = parse_json_object(text, file);
  if (!root) return root.error();
  UartBoardProfile p;
  p.file = file;
  Reader top(*root, file, "");
  auto kind = device_kind_of(*root, file);
  if (!kind) return kind.error();
  if (*kind == protocol::DeviceKind::Spigpu)
    return top.fail("device_kind", "missing or \"spigpu\": an spigpu board has a \"bridge\" (SPI), not a \"uart\"");
  p.device_kind = *kind;
  if (auto r = read_identity(top, p); !r) return r.error();
  const json* uart = top.get("uart");
  if (!uart || !uart->is_object()) return top.fail("uart", "missing (required object: vid, pid, interface, baud)");
  Reader u(*uart, file, "uart.");
  GPUBRIDGE_TRY_SET(p.vid, u.hex16("vid"));
  GPUBRIDGE_TRY_SET(p.pid, u.hex16("pid"));
  std::string iface;
  GPUBRIDGE_TRY_SET(iface, u.str("interface", "A"));
  if (iface.size() != 1 || iface[0] < 'A' || iface[0] > 'D') return u.fail("interface", "expected \"A\" to \"D\" (the USB interface)");
  p.interface = iface[0] - 'A';
  GPUBRIDGE_TRY_SET(p.serial, u.str("serial", ""));
  GPUBRIDGE_TRY_SET(p.tty, u.str("tty", ""));
  GPUBRIDGE_TRY_SET(p.baud, u.uint("baud", 300, 4000000, 115200));
  if (auto r = u.no_unknown_keys(); !r) return r.error();
  if (auto r = read_flash(top, file, p); !r) return r.error();
  if (auto r = top.no_unknown_keys(); !r) return r.error();
  return p;
}

Result<std::vector<UartBoardProfile>> load_uart_board_profiles(const std::filesystem::path& config_dir) {
  return load_dir<UartBoardProfile>(config_dir / "boards", "no board profile directory (set GPUBRIDGE_CONFIG_DIR or --config-dir)",
                                    &parse_uart_board_profile, &uart_board_file);
}

Result<UartBoardProfile> find_uart_board_profile(const std::filesystem::path& config_dir, const std::string& name) {
  if (name.size() > 5 && name.ends_with(".json")) {
    auto text = read_config_file(name);
    if (!text) return text.error();
    return parse_uart_board_profile(*text, name);
  }
  auto all = load_uart_board_profiles(config_dir);
  if (!all) return all.error();
  std::string names;
  if (auto* p = find_named(*all, name, names)) return std::move(*p);
  return make_error("no UART board profile named \"" + name + "\" in " + (config_dir / "boards").string() + " (known: " +
                        (names.empty() ? "none" : names) + "; `gpubridge boards` lists every board)",
                    backends::kBadRequest);
}

Result<std::vector<CableInfo>> load_cables(const std::filesystem::path& config_dir) {
  return load_dir<CableInfo>(config_dir / "cables", "no cable directory", &parse_cable);
}

}  // namespace gpubridge::usb
