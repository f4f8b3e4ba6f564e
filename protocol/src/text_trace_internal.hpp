#pragma once
// Shared between the text-trace reader and writer (not installed): tokens with columns and the
// register-line grammar, whose errors carry the column of the offending token.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::protocol::text {

struct Token {
  std::string_view text;
  std::size_t column = 1;  // 1-based byte column in the line
};
std::vector<Token> tokenize(std::string_view line);

struct LineError {
  std::size_t column = 1;
  std::string message;  // what is wrong; what to do
};

// A token as error messages show it: at most 40 bytes (cut at a character boundary, then "..."
// and the token's length), control bytes escaped (\0, \t, \xNN), so a 20 MB token or a NUL in
// it can neither flood nor cut the message.
std::string shown(std::string_view token);

// Decimal or 0x-hex unsigned integer that fits 64 bits (no sign, no fraction).
std::optional<std::uint64_t> parse_u64(std::string_view s);
bool iequals(std::string_view a, std::string_view b);

// Register line: `NAME`, `NAME value`, `NAME FIELD=value ...` or `0xIDX 0xDATA`.
std::optional<LineError> parse_register_tokens(std::span<const Token> tokens, Frame& out);

// "signed 12.4", "unsigned 0.32", "unsigned 24-bit": how a field's values are written.
std::string describe_field_format(const Field& f);

}  // namespace gpubridge::protocol::text
