#include "gpubridge/protocol/register_doc.hpp"

#include <cstdio>

#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::protocol {
namespace {

std::string hex(std::uint64_t v, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "0x%0*llX", digits, static_cast<unsigned long long>(v));
  return buf;
}

std::string bits(const Field& f) {
  if (f.width == 1) return "[" + std::to_string(f.lsb) + "]";
  return "[" + std::to_string(f.lsb + f.width - 1) + ":" + std::to_string(f.lsb) + "]";
}

std::string_view access_name(Access a) {
  switch (a) {
    case Access::ReadWrite: return "RW";
    case Access::WriteOnly: return "W";
    default: return "R";
  }
}

std::string kind_name(const Field& f) {
  switch (f.kind) {
    case FieldKind::Flag: return "flag";
    case FieldKind::Signed: return f.frac_bits ? "s" + std::to_string(f.width - f.frac_bits) + "." + std::to_string(f.frac_bits)
                                               : "s" + std::to_string(f.width);
    case FieldKind::Enum: {
      std::string s = "enum ";
      for (std::size_t i = 0; i < f.values.size(); ++i) {
        if (i) s += ", ";
        s += std::to_string(f.values[i].value) + " " + std::string(f.values[i].name);
      }
      return s;
    }
    default: return f.frac_bits ? "u" + std::to_string(f.width - f.frac_bits) + "." + std::to_string(f.frac_bits)
                                : "u" + std::to_string(f.width);
  }
}

}  // namespace

std::string register_table_markdown() {
  std::string out;
  out += "| Index | Name | Access | Path | Reset | Summary |\n|---|---|---|---|---|---|\n";
  for (const auto& r : register_table()) {
    out += "| " + hex(r.index, 2) + " | " + std::string(r.name) + " | " + std::string(access_name(r.access)) + " | " +
           (r.path == Path::Queued ? "queued" : "immediate") + " | " + hex(r.reset, 16) + " | " + std::string(r.summary) +
           " |\n";
  }
  out += "\nFields (bits not listed are reserved: write 0, read 0):\n\n";
  out += "| Register | Field | Bits | Type | Meaning |\n|---|---|---|---|---|\n";
  for (const auto& r : register_table()) {
    for (const auto& f : r.fields) {
      if (f.width == 0) {
        out += "| " + std::string(r.name) + " | - | [63:0] | reserved | " + std::string(f.doc) + " |\n";
        continue;
      }
      out += "| " + std::string(r.name) + " | " + std::string(f.name) + " | " + bits(f) + " | " + kind_name(f) + " | " +
             std::string(f.doc) + " |\n";
    }
  }
  return out;
}

}  // namespace gpubridge::protocol
