#pragma once
// Text traces (docs/protocol.md, "Traces"): one command per line, `#` comments.
//   NAME value                  raw register data (decimal or 0x hex); a decimal with a fraction
//                               sets the only field of a single-field fixed-point register
//   NAME FIELD=value ...        fields by name (enum names, exact fixed-point decimals); omitted fields are 0
//   0xIDX 0xDATA                raw frame, no checks beyond index ≤ 0x7F
//   .upload ADDR png FILE [FORMAT] | .upload ADDR hex FILE | .mem ADDR HEXBYTES
//   .fence ID | .read NAME | .readback ADDR LENGTH | .batch | .meta JSON
// Errors read "FILE:LINE:COL: what is wrong; what to do". This library does no I/O: files named
// by .upload are turned into bytes by an AssetLoader (common/trace_files.hpp provides one).
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/command_stream.hpp"

namespace gpubridge::protocol {

// A file an .upload directive refers to, exactly as written in the trace (relative paths are the
// loader's business: resolve them against the trace file's directory).
struct TraceAsset {
  enum class Kind { Png, Hex };
  Kind kind = Kind::Png;
  std::string path;
  PixelFormat format = PixelFormat::RGBA8888;  // PNG conversion target
};
// Returns the device bytes for an asset; error messages need no location (the reader adds it).
using AssetLoader = std::function<Result<std::vector<std::uint8_t>>(const TraceAsset&)>;

// Parses a whole text trace. `loader` may be empty when the trace has no .upload directives.
Result<CommandStream> parse_text_trace(std::string_view text, std::string_view file_name, const AssetLoader& loader);

// Canonical text form (round-trippable: parse(write(s)) reproduces s except timestamps).
std::string write_text_trace(const CommandStream& s);

// One register write in text form: "VERTEX Z=0x100 Y=10.5 X=-3"; raw "0x42 0x..." when the
// value cannot be expressed by field names (undefined register, reserved bits, undefined enum value).
std::string format_register_write(std::uint8_t index, std::uint64_t data);
// Parses one register line (no directives, no comment); errors read "column N: what; what to do".
Result<Frame> parse_register_line(std::string_view line);

// Whitespace-separated hex bytes ("0a 1B ff", optional 0x prefixes) as used by hex asset files.
Result<std::vector<std::uint8_t>> parse_hex_bytes(std::string_view text);

// Exact decimal form of a fixed-point field value: raw / 2^frac_bits ("-3.5", "0.0625");
// frac_bits ≤ 32 (the widest fraction in the register table).
std::string format_fixed(std::int64_t raw, unsigned frac_bits);

}  // namespace gpubridge::protocol
