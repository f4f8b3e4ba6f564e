// Text-trace values: integers, exact fixed-point decimals, enum names, and the register-line
// grammar shared by the reader and `parse_register_line`.
#include <algorithm>
#include <cctype>
#include <cstdio>

#include "gpubridge/protocol/text_trace.hpp"
#include "text_trace_internal.hpp"

namespace gpubridge::protocol {
namespace text {
namespace {

using u128 = unsigned __int128;

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

std::string u128_to_string(u128 v) {
  if (v == 0) return "0";
  std::string s;
  while (v > 0) {
    s.push_back(static_cast<char>('0' + static_cast<int>(v % 10)));
    v /= 10;
  }
  std::reverse(s.begin(), s.end());
  return s;
}

// Raw range of a field as integers.
struct RawRange {
  __int128 min, max;
};
RawRange raw_range(const Field& f) {
  if (f.kind == FieldKind::Signed)
    return {-(static_cast<__int128>(1) << (f.width - 1)), (static_cast<__int128>(1) << (f.width - 1)) - 1};
  return {0, (static_cast<__int128>(1) << f.width) - 1};
}

std::string format_raw_as_value(const Field& f, __int128 raw) {
  if (f.frac_bits == 0) {
    return raw < 0 ? "-" + u128_to_string(static_cast<u128>(-raw)) : u128_to_string(static_cast<u128>(raw));
  }
  return format_fixed(static_cast<std::int64_t>(raw), f.frac_bits);
}

// Parses `[-]digits[.digits]` exactly as raw = value * 2^frac. Returns an error text on failure.
std::optional<std::string> parse_decimal_raw(std::string_view s, const Field& f, __int128& raw) {
  bool negative = false;
  std::size_t i = 0;
  if (i < s.size() && (s[i] == '-' || s[i] == '+')) negative = s[i++] == '-';
  std::string_view int_part, frac_part;
  const std::size_t dot = s.find('.', i);
  int_part = s.substr(i, dot == std::string_view::npos ? std::string_view::npos : dot - i);
  if (dot != std::string_view::npos) frac_part = s.substr(dot + 1);
  const auto all_digits = [](std::string_view d) {
    return std::all_of(d.begin(), d.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if ((int_part.empty() && frac_part.empty()) || !all_digits(int_part) || !all_digits(frac_part))
    return std::string("is not a number");
  // Leading zeros are harmless; anything beyond 20 significant integer digits cannot fit 64 bits.
  while (int_part.size() > 1 && int_part[0] == '0') int_part.remove_prefix(1);
  while (!frac_part.empty() && frac_part.back() == '0') frac_part.remove_suffix(1);
  if (int_part.size() > 20) return std::string("is out of range");
  u128 ip = 0;
  for (char c : int_part) ip = ip * 10 + static_cast<unsigned>(c - '0');
  const unsigned frac = f.frac_bits;
  // value = ip + F / 10^d must equal raw / 2^frac. With d ≤ frac this holds iff F is a multiple
  // of 5^d; then raw's fractional part is (F / 5^d) * 2^(frac - d). d > frac is never exact.
  const std::size_t d = frac_part.size();
  if (d > frac) return std::string();  // empty text = "not a multiple"
  u128 fp = 0, pow5 = 1;
  for (char c : frac_part) fp = fp * 10 + static_cast<unsigned>(c - '0');
  for (std::size_t k = 0; k < d; ++k) pow5 *= 5;
  if (fp % pow5 != 0) return std::string();
  const u128 magnitude = (ip << frac) + ((fp / pow5) << (frac - d));
  if (magnitude > (static_cast<u128>(1) << 64)) return std::string("is out of range");
  raw = negative ? -static_cast<__int128>(magnitude) : static_cast<__int128>(magnitude);
  return std::nullopt;
}

std::string enum_names(const Field& f) {
  std::string out;
  for (const auto& v : f.values) {
    if (!out.empty()) out += ", ";
    out += v.name;
  }
  return out;
}

std::string field_names(const RegisterDesc& r) {
  std::string out;
  for (const auto& f : r.fields) {
    if (f.width == 0) continue;
    if (!out.empty()) out += ", ";
    out += f.name;
  }
  return out.empty() ? "(none: it takes no value)" : out;
}

std::string hex(std::uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%llX", static_cast<unsigned long long>(v));
  return buf;
}

std::string raw_index(std::uint8_t index) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", index);
  return buf;
}

// Value of one field from its text; `item` is "FIELD=value" as messages show it.
std::optional<std::string> parse_field_value(const Field& f, std::string_view v, const std::string& item,
                                             std::uint64_t& bits) {
  if (v.empty()) return item + " has no value; write " + std::string(f.name) + "=<value>";
  if (f.kind == FieldKind::Enum) {
    for (const auto& e : f.values) {
      if (iequals(e.name, v)) {
        bits = e.value;
        return std::nullopt;
      }
    }
    if (auto n = parse_u64(v)) {
      for (const auto& e : f.values) {
        if (e.value == *n) {
          bits = *n;
          return std::nullopt;
        }
      }
    }
    return item + " is not a " + std::string(f.name) + " value; use one of " + enum_names(f);
  }
  if (f.kind == FieldKind::Flag) {
    if (v == "0" || v == "1") {
      bits = v == "1" ? 1 : 0;
      return std::nullopt;
    }
    return item + " is not a flag value; use 0 or 1";
  }
  const auto range = raw_range(f);
  const std::string fmt = describe_field_format(f);
  const std::string range_text = format_raw_as_value(f, range.min) + ".." + format_raw_as_value(f, range.max);
  if (v.size() > 2 && v[0] == '0' && (v[1] == 'x' || v[1] == 'X')) {
    // Hex gives the field's raw bits (two's complement for signed fields).
    auto n = parse_u64(v);
    if (!n || (f.width < 64 && *n >> f.width))
      return item + " does not fit the " + std::to_string(f.width) + "-bit field " + std::string(f.name) +
             "; raw hex bits must be below " + hex(f.width < 64 ? (1ull << f.width) : 0) + " (" + fmt + ")";
    bits = *n;
    return std::nullopt;
  }
  __int128 raw = 0;
  if (auto problem = parse_decimal_raw(v, f, raw)) {
    if (problem->empty()) {
      if (f.frac_bits == 0)
        return item + " is not an integer (" + std::string(f.name) + " is " + fmt + ")";
      return item + " is not a multiple of 1/" + u128_to_string(static_cast<u128>(1) << f.frac_bits) + " (" +
             std::string(f.name) + " is " + fmt + "); round it to a representable value";
    }
    if (*problem == "is out of range")
      return item + " is out of range " + range_text + " (" + std::string(f.name) + " is " + fmt + ")";
    return item + " " + *problem + "; write a decimal, a 0x hex value" +
           (f.frac_bits ? std::string(" or a decimal fraction") : std::string());
  }
  if (raw < range.min || raw > range.max)
    return item + " is out of range " + range_text + " (" + std::string(f.name) + " is " + fmt + ")";
  bits = static_cast<std::uint64_t>(raw) & (f.width >= 64 ? ~0ull : ((1ull << f.width) - 1));
  return std::nullopt;
}

std::optional<LineError> parse_named(const RegisterDesc& r, std::span<const Token> tokens, Frame& out) {
  const std::string name(r.name);
  if (r.access == Access::ReadOnly)
    return LineError{tokens[0].column, name + " is read-only; use `.read " + name +
                                           "` to read it (the raw form 0xIDX 0xDATA sends a write anyway)"};
  out = Frame{false, r.index, 0};
  if (tokens.size() == 1) return std::nullopt;  // omitted fields are 0

  const bool field_form = tokens[1].text.find('=') != std::string_view::npos;
  if (!field_form) {
    if (tokens.size() > 2)
      return LineError{tokens[2].column, "unexpected '" + shown(tokens[2].text) + "' after the value of " + name +
                                             "; write either `" + name + " value` or `" + name + " FIELD=value ...`"};
    const Token& v = tokens[1];
    const bool fractional = v.text.find('.') != std::string_view::npos;
    const Field* only = nullptr;
    std::size_t nfields = 0;
    for (const auto& f : r.fields)
      if (f.width > 0) ++nfields, only = &f;
    if (fractional || (v.text.size() > 0 && v.text[0] == '-')) {
      if (nfields != 1)
        return LineError{v.column, "a fractional or negative value needs a single-field register; " + name +
                                       " has fields " + field_names(r) + ": write " + name + " FIELD=value ..."};
      std::uint64_t bits = 0;
      if (auto e = parse_field_value(*only, v.text, std::string(only->name) + "=" + shown(v.text), bits))
        return LineError{v.column, *e};
      out.data = only->put(0, bits);
      return std::nullopt;
    }
    auto n = parse_u64(v.text);
    if (!n)
      return LineError{v.column, "'" + shown(v.text) + "' is not a value for " + name +
                                     "; write a decimal or 0x hex number, or FIELD=value pairs (fields: " +
                                     field_names(r) + ")"};
    const auto check = check_write(r.index, *n);
    if (check.errors != 0)
      return LineError{v.column, "value " + hex(*n) + " is not valid for " + name + " (" + check.problem +
                                     "); set fields by name, or use the raw form " + raw_index(r.index) + " " + hex(*n) +
                                     " to send it anyway"};
    out.data = *n;
    return std::nullopt;
  }

  std::uint64_t assigned = 0;  // masks of the fields already set on this line
  for (std::size_t i = 1; i < tokens.size(); ++i) {
    const Token& t = tokens[i];
    const auto eq = t.text.find('=');
    if (eq == std::string_view::npos)
      return LineError{t.column, "expected FIELD=value, found '" + shown(t.text) + "' (fields of " + name +
                                     ": " + field_names(r) + ")"};
    const auto fname = t.text.substr(0, eq);
    const Field* f = r.field(fname);
    if (!f)
      return LineError{t.column, "unknown field '" + shown(fname) + "' of " + name + "; its fields are " +
                                     field_names(r)};
    if (assigned & f->mask())
      return LineError{t.column, "field " + std::string(f->name) + " is set twice; set it once"};
    assigned |= f->mask();
    std::uint64_t bits = 0;
    if (auto e = parse_field_value(*f, t.text.substr(eq + 1), shown(t.text), bits)) return LineError{t.column, *e};
    out.data = f->put(out.data, bits);
  }
  return std::nullopt;
}

}  // namespace

std::string shown(std::string_view token) {
  constexpr std::size_t kShownBytes = 40;
  std::size_t cut = token.size();
  if (cut > kShownBytes) {
    cut = kShownBytes;  // a UTF-8 continuation byte (10xxxxxx) never starts the cut-off tail
    while (cut > 0 && (static_cast<unsigned char>(token[cut]) & 0xC0) == 0x80) --cut;
  }
  std::string out;
  for (const char c : token.substr(0, cut)) {
    const auto u = static_cast<unsigned char>(c);
    if (u == 0) out += "\\0";
    else if (u == '\t') out += "\\t";
    else if (u < 0x20 || u == 0x7F) out += "\\x" + std::string(1, "0123456789ABCDEF"[u >> 4]) + "0123456789ABCDEF"[u & 15];
    else out += c;
  }
  if (cut < token.size()) out += "... (" + std::to_string(token.size()) + " bytes)";
  return out;
}

std::vector<Token> tokenize(std::string_view line) {
  std::vector<Token> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    if (i >= line.size()) break;
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    out.push_back(Token{line.substr(start, i - start), start + 1});
  }
  return out;
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::toupper(static_cast<unsigned char>(x)) == std::toupper(static_cast<unsigned char>(y));
         });
}

std::optional<std::uint64_t> parse_u64(std::string_view s) {
  unsigned base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    base = 16;
    s.remove_prefix(2);
  }
  if (s.empty()) return std::nullopt;
  std::uint64_t v = 0;
  for (char c : s) {
    unsigned digit;
    if (c >= '0' && c <= '9') digit = static_cast<unsigned>(c - '0');
    else if (base == 16 && c >= 'a' && c <= 'f') digit = static_cast<unsigned>(c - 'a' + 10);
    else if (base == 16 && c >= 'A' && c <= 'F') digit = static_cast<unsigned>(c - 'A' + 10);
    else if (c == '_') continue;  // digit separator: 0xFFFF_0000
    else return std::nullopt;
    if (v > (~0ull - digit) / base) return std::nullopt;  // overflow
    v = v * base + digit;
  }
  return v;
}

std::string describe_field_format(const Field& f) {
  const bool is_signed = f.kind == FieldKind::Signed;
  const std::string sign = is_signed ? "signed " : "unsigned ";
  if (f.frac_bits == 0) return sign + std::to_string(f.width) + "-bit integer";
  return sign + std::to_string(f.width - f.frac_bits) + "." + std::to_string(f.frac_bits);
}

std::optional<LineError> parse_register_tokens(std::span<const Token> tokens, Frame& out) {
  if (tokens.empty()) return LineError{1, "empty command"};
  const Token& first = tokens[0];
  if (!first.text.empty() && first.text[0] >= '0' && first.text[0] <= '9') {
    auto idx = parse_u64(first.text);
    if (!idx || *idx > 0x7F)
      return LineError{first.column, "'" + shown(first.text) +
                                         "' is not a register index; raw frames are `0xIDX 0xDATA` with IDX ≤ 0x7F"};
    if (tokens.size() != 2)
      return LineError{tokens.size() < 2 ? first.column + first.text.size() : tokens[2].column,
                       "a raw frame is exactly `0xIDX 0xDATA`"};
    auto data = parse_u64(tokens[1].text);
    if (!data)
      return LineError{tokens[1].column, "'" + shown(tokens[1].text) +
                                             "' is not a 64-bit value; write decimal or 0x hex (at most 16 hex digits)"};
    out = Frame{false, static_cast<std::uint8_t>(*idx), *data};
    return std::nullopt;
  }
  const RegisterDesc* r = find_register(first.text);
  if (!r)
    return LineError{first.column, "unknown register '" + shown(first.text) +
                                       "'; run `gpubridge regs` for the names, or write a raw frame 0xIDX 0xDATA"};
  return parse_named(*r, tokens, out);
}

}  // namespace text

std::string format_fixed(std::int64_t raw, unsigned frac_bits) {
  using text::u128;
  const bool negative = raw < 0;
  const u128 mag = negative ? static_cast<u128>(-static_cast<__int128>(raw)) : static_cast<u128>(raw);
  frac_bits = std::min(frac_bits, 32u);  // the table's widest fraction; keeps fp * 5^f inside 128 bits
  const u128 ip = mag >> frac_bits;
  const u128 fp = mag & ((static_cast<u128>(1) << frac_bits) - 1);
  std::string out = (negative ? "-" : "") + text::u128_to_string(ip);
  if (fp == 0 || frac_bits == 0) return out;
  // fp / 2^f = fp * 5^f / 10^f: exactly f decimal digits, then strip trailing zeros.
  u128 pow5 = 1;
  for (unsigned k = 0; k < frac_bits; ++k) pow5 *= 5;
  std::string digits = text::u128_to_string(fp * pow5);
  digits.insert(0, frac_bits - digits.size(), '0');
  while (!digits.empty() && digits.back() == '0') digits.pop_back();
  return out + "." + digits;
}

std::string format_register_write(std::uint8_t index, std::uint64_t data) {
  const RegisterDesc* r = find_register(index);
  char raw[48];
  std::snprintf(raw, sizeof raw, "0x%02X 0x%016llX", index, static_cast<unsigned long long>(data));
  if (!r || r->access == Access::ReadOnly || check_write(index, data).errors != 0) return raw;
  std::size_t nfields = 0;
  for (const auto& f : r->fields) nfields += f.width > 0;
  std::string out(r->name);
  for (const auto& f : r->fields) {
    if (f.width == 0) continue;
    const std::uint64_t v = f.get(data);
    if (v == 0 && nfields > 1) continue;  // omitted fields are 0
    out += ' ';
    out += f.name;
    out += '=';
    if (f.kind == FieldKind::Enum) {
      for (const auto& e : f.values)
        if (e.value == v) out += e.name;
    } else if (f.kind == FieldKind::Flag) {
      out += v ? '1' : '0';
    } else if (f.frac_bits > 0) {
      out += format_fixed(f.kind == FieldKind::Signed ? f.get_signed(data) : static_cast<std::int64_t>(v), f.frac_bits);
    } else if (f.kind == FieldKind::Signed) {
      out += std::to_string(f.get_signed(data));
    } else if (f.width > 16) {
      out += text::hex(v);
    } else {
      out += std::to_string(v);
    }
  }
  return out;
}

Result<Frame> parse_register_line(std::string_view line) {
  const auto tokens = text::tokenize(line);
  Frame f;
  if (auto e = text::parse_register_tokens(tokens, f))
    return make_error("column " + std::to_string(e->column) + ": " + e->message);
  return f;
}

Result<std::vector<std::uint8_t>> parse_hex_bytes(std::string_view s) {
  std::vector<std::uint8_t> out;
  std::size_t line = 1, col = 1;
  std::size_t i = 0;
  const auto nibble = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  while (i < s.size()) {
    const char c = s[i];
    if (c == '\n') {
      ++line, col = 1, ++i;
      continue;
    }
    if (text::is_space(c)) {
      ++col, ++i;
      continue;
    }
    if (c == '#') {  // comment to end of line
      while (i < s.size() && s[i] != '\n') ++i;
      continue;
    }
    std::size_t start = i;
    while (i < s.size() && !text::is_space(s[i]) && s[i] != '\n' && s[i] != '#') ++i;
    std::string_view tok = s.substr(start, i - start);
    const std::size_t tok_col = col;
    col += tok.size();
    if (tok.size() > 2 && tok[0] == '0' && (tok[1] == 'x' || tok[1] == 'X')) tok.remove_prefix(2);
    if (tok.size() % 2 != 0)
      return make_error(std::to_string(line) + ":" + std::to_string(tok_col) + ": '" + text::shown(tok) +
                        "' has an odd number of hex digits; write whole bytes (two digits each)");
    for (std::size_t k = 0; k < tok.size(); k += 2) {
      const int hi = nibble(tok[k]), lo = nibble(tok[k + 1]);
      if (hi < 0 || lo < 0)
        return make_error(std::to_string(line) + ":" + std::to_string(tok_col) + ": '" + text::shown(tok) +
                          "' is not hex bytes; use digits 0-9 and a-f");
      out.push_back(static_cast<std::uint8_t>(hi * 16 + lo));
    }
  }
  return out;
}

}  // namespace gpubridge::protocol
