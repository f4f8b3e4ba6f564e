#include "gpubridge/dmc1/stream.hpp"

#include <cctype>
#include <cstdio>
#include <fstream>

#include "gpubridge/common/regular_file.hpp"
#include "gpubridge/protocol/trace.hpp"

namespace gpubridge::dmc1 {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// The offending text for a message: at most 40 characters, non-printable bytes as \xNN.
std::string quote(std::string_view s) {
  std::string q = "'";
  for (std::size_t i = 0; i < s.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (std::isprint(c)) {
      q += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      q += buf;
    }
  }
  if (s.size() > 40) q += "...";
  return q + "'";
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Calls f(line_number, line) for every line (without its terminator).
template <class F>
Result<void> for_each_line(std::string_view text, F&& f) {
  std::size_t number = 0;
  while (!text.empty()) {
    ++number;
    const std::size_t nl = text.find('\n');
    const std::string_view line = text.substr(0, nl);
    text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
    if (auto r = f(number, line); !r) return r;
  }
  return {};
}

// An integer as Python's int(x, 0) reads it: decimal, 0x hex, 0o octal or 0b binary.
std::optional<std::uint64_t> parse_auto_base(std::string_view s) {
  unsigned base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) base = 16;
  else if (s.size() > 2 && s[0] == '0' && (s[1] == 'o' || s[1] == 'O')) base = 8;
  else if (s.size() > 2 && s[0] == '0' && (s[1] == 'b' || s[1] == 'B')) base = 2;
  if (base != 10) s.remove_prefix(2);
  else if (s.size() > 1 && s[0] == '0') return std::nullopt;  // Python refuses decimal with leading zeros
  if (s.empty()) return std::nullopt;
  std::uint64_t v = 0;
  for (const char c : s) {
    const int d = hex_digit(c);
    if (d < 0 || static_cast<unsigned>(d) >= base) return std::nullopt;
    if (v > (~0ull - static_cast<unsigned>(d)) / base) return std::nullopt;  // overflow
    v = v * base + static_cast<unsigned>(d);
  }
  return v;
}

std::string_view extension_lower(const std::filesystem::path& p, std::string& storage) {
  storage = p.extension().string();
  for (auto& c : storage) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return storage;
}

}  // namespace

std::string_view to_string(StreamFormat f) { return f == StreamFormat::Text ? "dmc1" : "nfo"; }

std::optional<StreamFormat> stream_format_for_path(const std::filesystem::path& path) {
  std::string storage;
  const std::string_view ext = extension_lower(path, storage);
  if (ext == ".dmc1") return StreamFormat::Text;
  if (ext == ".nfo") return StreamFormat::Lines;
  return std::nullopt;
}

StreamFormat sniff_stream_format(std::string_view text) {
  std::optional<StreamFormat> found;
  (void)for_each_line(text, [&](std::size_t, std::string_view line) -> Result<void> {
    line = trim(line.substr(0, line.find('#')));
    if (!found && !line.empty()) found = line.find(',') != std::string_view::npos ? StreamFormat::Lines : StreamFormat::Text;
    return {};
  });
  return found.value_or(StreamFormat::Text);
}

Result<std::vector<std::uint64_t>> parse_text_stream(std::string_view text, const std::string& name) {
  std::vector<std::uint64_t> words;
  auto r = for_each_line(text, [&](std::size_t number, std::string_view line) -> Result<void> {
    const std::string_view body = trim(line.substr(0, line.find('#')));
    if (body.empty()) return {};
    std::uint64_t w = 0;
    bool ok = body.size() == 16;
    for (std::size_t i = 0; ok && i < 16; ++i) {
      const int d = hex_digit(body[i]);
      ok = d >= 0;
      w = w << 4 | static_cast<unsigned>(d < 0 ? 0 : d);
    }
    if (!ok)
      return make_error(name + ":" + std::to_string(number) + ": " + quote(body) +
                        " is not a command word; write one command per line as 16 hex digits (tex0 << 32 | tex1), "
                        "e.g. 00000000c0000001 for an end of column");
    words.push_back(w);
    return {};
  });
  if (!r) return r.error();
  return words;
}

Result<std::vector<std::uint64_t>> parse_line_stream(std::string_view text, const std::string& name) {
  std::vector<std::uint64_t> words;
  auto r = for_each_line(text, [&](std::size_t number, std::string_view line) -> Result<void> {
    const std::string_view body = trim(line);
    if (body.empty()) return {};
    const std::string where = name + ":" + std::to_string(number) + ": ";
    std::string_view rest = body;
    std::uint64_t w = 0;
    for (unsigned field = 0; field < 9; ++field) {
      const std::size_t comma = rest.find(',');
      if (comma == std::string_view::npos && field < 8)
        return make_error(where + quote(body) + " has " + std::to_string(field + 1) +
                          " field(s); a command line is `timestamp,b0,b1,b2,b3,b4,b5,b6,b7,` (9 comma-separated numbers)");
      const std::string_view item = trim(rest.substr(0, comma));
      rest.remove_prefix(comma == std::string_view::npos ? rest.size() : comma + 1);
      const auto v = parse_auto_base(item);
      if (!v)
        return make_error(where + "field " + std::to_string(field + 1) + " " + quote(item) +
                          " is not a number (write decimal, 0x.. hex, 0o.. octal or 0b.. binary)");
      if (field == 0) continue;  // the timestamp: monitor_send.py ignores it
      if (*v > 255)
        return make_error(where + "byte b" + std::to_string(field - 1) + " = " + std::to_string(*v) +
                          " does not fit in a byte (0..255)");
      w = w << 8 | *v;
    }
    if (!trim(rest).empty())
      return make_error(where + quote(body) + " has more than 9 fields; a command line is `timestamp,b0,...,b7,`");
    words.push_back(w);
    return {};
  });
  if (!r) return r.error();
  return words;
}

Result<std::vector<std::uint64_t>> parse_stream(std::string_view text, StreamFormat f, const std::string& name) {
  return f == StreamFormat::Text ? parse_text_stream(text, name) : parse_line_stream(text, name);
}

std::string format_text_stream(std::span<const std::uint64_t> words, std::string_view header) {
  std::string out;
  out.reserve(words.size() * 17 + header.size() + 16);
  while (!header.empty()) {
    const std::size_t nl = header.find('\n');
    out += "# ";
    out += header.substr(0, nl);
    out += '\n';
    header.remove_prefix(nl == std::string_view::npos ? header.size() : nl + 1);
  }
  char buf[24];
  for (const std::uint64_t w : words) {
    std::snprintf(buf, sizeof buf, "%016llx\n", static_cast<unsigned long long>(w));
    out += buf;
  }
  return out;
}

std::string format_line_stream(std::span<const std::uint64_t> words) {
  std::string out;
  out.reserve(words.size() * 42);
  char buf[8];
  for (const std::uint64_t w : words) {
    out += "0,";
    for (int b = 7; b >= 0; --b) {
      std::snprintf(buf, sizeof buf, "0x%02x,", static_cast<unsigned>((w >> (8 * b)) & 0xFF));
      out += buf;
    }
    out += '\n';
  }
  return out;
}

Result<LoadedStream> load_stream(const std::filesystem::path& path) {
  auto data = read_regular_file(path, kMaxStreamFileBytes, "DMC-1 stream");
  if (!data) return data.error();
  LoadedStream s;
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(data->data()), data->size());
  if (protocol::looks_like_binary_trace(bytes)) {
    // A recording of a DMC-1 session (gpubridged --record); a spigpu trace is refused by its kind.
    auto kind = protocol::binary_trace_device_kind(bytes, path.string());
    if (!kind) return kind.error();
    if (*kind != protocol::DeviceKind::Dmc1)
      return make_error(path.string() + ": is a gpubridge binary trace of a " +
                        std::string(protocol::device_kind_info(*kind).label) +
                        " (metadata \"device_kind\"), not of a DMC-1; play it to a daemon serving one, or render it without --device dmc1");
    auto words = protocol::read_dmc1_trace(bytes, path.string());
    if (!words) return words.error();
    s.words = std::move(words).value();
    s.binary_trace = true;
    return s;
  }
  s.format = stream_format_for_path(path).value_or(sniff_stream_format(*data));
  auto words = parse_stream(*data, s.format, path.string());
  if (!words) return words.error();
  s.words = std::move(words).value();
  return s;
}

Result<void> save_stream(const std::filesystem::path& path, std::span<const std::uint64_t> words,
                         std::optional<StreamFormat> format) {
  const StreamFormat f = format.value_or(stream_format_for_path(path).value_or(StreamFormat::Text));
  const std::string text = f == StreamFormat::Text ? format_text_stream(words) : format_line_stream(words);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return make_error(path.string() + ": cannot create the stream file (check the directory exists and is writable)");
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) return make_error(path.string() + ": write failed (disk full?)");
  return {};
}

}  // namespace gpubridge::dmc1
