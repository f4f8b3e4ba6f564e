#pragma once
// Trace files on disk: format detection, loading (both formats) and saving, and the asset loader
// that turns text-trace `.upload` directives into device bytes. protocol/ parses bytes; this is
// where files are opened. Relative directive paths resolve against the trace file's directory.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/text_trace.hpp"
#include "gpubridge/protocol/trace.hpp"

namespace gpubridge {

enum class TraceFormat { Binary, Text };

inline constexpr std::uint64_t kMaxTextTraceBytes = 256ull << 20;  // text traces are read whole
inline constexpr std::uint64_t kMaxTraceAssetBytes = 64ull << 20;  // one .upload file (hex or converted PNG)

// By extension: .gbt / .gbtrace → Binary; .trace / .txt → Text; anything else → nullopt.
std::optional<TraceFormat> trace_format_for_path(const std::filesystem::path& path);

// Loads .upload assets: PNG (converted to the directive's pixel format) or whitespace-separated
// hex bytes, relative paths resolved against base_dir.
protocol::AssetLoader make_asset_loader(std::filesystem::path base_dir);

// Reads a trace of either format (binary is recognised by its magic, whatever the extension).
Result<protocol::CommandStream> load_trace(const std::filesystem::path& path);
// Writes `s` in `format`, or the format implied by the extension when format is nullopt.
Result<void> save_trace(const std::filesystem::path& path, const protocol::CommandStream& s,
                        std::optional<TraceFormat> format = std::nullopt);

// Streams a binary trace from a file (bounded memory, for long recordings).
class FileSource final : public protocol::ByteSource {
 public:
  static Result<std::unique_ptr<FileSource>> open(const std::filesystem::path& path);
  ~FileSource() override;
  FileSource(const FileSource&) = delete;
  FileSource& operator=(const FileSource&) = delete;
  Result<std::size_t> read(std::span<std::uint8_t> out) override;

 private:
  FileSource(std::FILE* f, std::string name) : file_(f), name_(std::move(name)) {}
  std::FILE* file_;
  std::string name_;
};

}  // namespace gpubridge
