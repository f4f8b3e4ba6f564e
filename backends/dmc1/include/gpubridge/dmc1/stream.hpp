#pragma once
// DMC-1 command streams as files (docs/dmc1.md, "Stream files"):
//   .dmc1  text, one command per line as 16 hex digits (the word tex0 << 32 | tex1), `#` comments,
//          blank lines ignored (the format of the RTL goldens);
//   .nfo   tinygpus' monitor_send.py lines `timestamp,b0,...,b7,` (timestamp ignored, bytes in
//          base 10, 0x hex, 0o octal or 0b binary; b0 is bits 63:56, the byte sent first over UART).
// Parsers never do I/O; errors are "NAME:LINE: what is wrong; what to do".
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gpubridge/common/result.hpp"

namespace gpubridge::dmc1 {

enum class StreamFormat { Text, Lines };
std::string_view to_string(StreamFormat f);  // "dmc1" | "nfo"

inline constexpr std::uint64_t kMaxStreamFileBytes = 256ull << 20;

// By extension: .dmc1 -> Text, .nfo -> Lines; otherwise nullopt.
std::optional<StreamFormat> stream_format_for_path(const std::filesystem::path& path);
// For files without a known extension: Lines when the first command line holds a comma.
StreamFormat sniff_stream_format(std::string_view text);

Result<std::vector<std::uint64_t>> parse_text_stream(std::string_view text, const std::string& name);
Result<std::vector<std::uint64_t>> parse_line_stream(std::string_view text, const std::string& name);
Result<std::vector<std::uint64_t>> parse_stream(std::string_view text, StreamFormat f, const std::string& name);

// `header` lines are written as `# ` comments before the commands (text format only).
std::string format_text_stream(std::span<const std::uint64_t> words, std::string_view header = {});
std::string format_line_stream(std::span<const std::uint64_t> words);

struct LoadedStream {
  StreamFormat format = StreamFormat::Text;
  bool binary_trace = false;  // read from a gpubridge binary trace of a DMC-1 session (format unused)
  std::vector<std::uint64_t> words;
};
// Reads a stream file (format by extension, else sniffed), or a gpubridge binary trace whose metadata
// says "device_kind": "dmc1" (a recorded DMC-1 session, docs/protocol.md 18.1); a binary trace of
// another device kind is refused with a message.
Result<LoadedStream> load_stream(const std::filesystem::path& path);
Result<void> save_stream(const std::filesystem::path& path, std::span<const std::uint64_t> words,
                         std::optional<StreamFormat> format = std::nullopt);

}  // namespace gpubridge::dmc1
