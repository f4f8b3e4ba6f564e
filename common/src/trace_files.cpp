// Trace files: the I/O half of traces (protocol/ does the parsing).
#include "gpubridge/common/trace_files.hpp"

#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/regular_file.hpp"

namespace gpubridge {
namespace {

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

std::optional<TraceFormat> trace_format_for_path(const std::filesystem::path& path) {
  const std::string ext = lower(path.extension().string());
  if (ext == ".gbt" || ext == ".gbtrace") return TraceFormat::Binary;  // .gbtrace: daemon recordings
  if (ext == ".trace" || ext == ".txt") return TraceFormat::Text;
  return std::nullopt;
}

protocol::AssetLoader make_asset_loader(std::filesystem::path base_dir) {
  return [base = std::move(base_dir)](const protocol::TraceAsset& asset) -> Result<std::vector<std::uint8_t>> {
    std::filesystem::path p(asset.path);
    if (p.is_relative()) p = base / p;
    if (asset.kind == protocol::TraceAsset::Kind::Hex) {
      auto text = read_regular_file(p, kMaxTraceAssetBytes * 3, "hex file");  // ≥ 2 characters per byte
      if (!text) return text.error();
      auto bytes = protocol::parse_hex_bytes(*text);
      if (!bytes) return make_error(p.string() + ":" + bytes.error().message);
      return std::move(bytes).value();
    }
    // The asset limit, in pixels of the target format, is checked against the PNG's header.
    PngLimits limits;
    limits.max_pixels = kMaxTraceAssetBytes / protocol::bytes_per_pixel(asset.format);
    limits.purpose = "an .upload of " + std::string(protocol::to_string(asset.format)) + " (at most " +
                     std::to_string(kMaxTraceAssetBytes) + " bytes)";
    auto img = load_png(p, limits);
    if (!img) return img.error();
    return device_from_image(asset.format, *img);
  };
}

Result<protocol::CommandStream> load_trace(const std::filesystem::path& path) {
  if (auto r = check_regular_file(path, "trace"); !r) return r.error();
  auto src = FileSource::open(path);
  if (!src) return src.error();
  std::uint8_t magic[sizeof protocol::kTraceMagic] = {};
  auto n = (*src)->read(magic);
  if (!n) return n.error();
  if (protocol::looks_like_binary_trace(std::span(magic, *n))) {
    src = FileSource::open(path);  // start again at byte 0
    if (!src) return src.error();
    protocol::BinaryTraceReader reader(**src, path.string());
    if (auto r = reader.open(); !r) return r.error();
    protocol::CommandStream s;
    s.metadata_json = reader.metadata_json();
    for (;;) {
      protocol::TimedCommand c;
      auto more = reader.next(c);
      if (!more) return more.error();
      if (!*more) return s;
      s.commands.push_back(std::move(c));
    }
  }
  if (trace_format_for_path(path) == TraceFormat::Binary)
    return make_error(path.string() + ": not a binary trace (no GBTRACE magic) although named .gbt");
  auto text = read_regular_file(path, kMaxTextTraceBytes, "text trace");
  if (!text) return text.error();
  return protocol::parse_text_trace(*text, path.string(), make_asset_loader(path.parent_path()));
}

Result<void> save_trace(const std::filesystem::path& path, const protocol::CommandStream& s,
                        std::optional<TraceFormat> format) {
  if (!format) format = trace_format_for_path(path);
  if (!format)
    return make_error(path.string() + ": cannot tell the trace format from the extension; use .gbt (binary) or "
                      ".trace/.txt (text), or pass the format explicitly");
  std::string text;
  std::vector<std::uint8_t> binary;
  if (*format == TraceFormat::Binary) {
    auto b = protocol::write_binary_trace(s);
    if (!b) return make_error(path.string() + ": " + b.error().message);
    binary = std::move(b).value();
  } else {
    text = protocol::write_text_trace(s);
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return make_error(path.string() + ": cannot create file (" + std::strerror(errno) + ")");
  if (*format == TraceFormat::Binary)
    out.write(reinterpret_cast<const char*>(binary.data()), static_cast<std::streamsize>(binary.size()));
  else
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) return make_error(path.string() + ": write failed (disk full?)");
  return {};
}

Result<std::unique_ptr<FileSource>> FileSource::open(const std::filesystem::path& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return make_error(path.string() + ": cannot open (" + std::strerror(errno) + ")");
  return std::unique_ptr<FileSource>(new FileSource(f, path.string()));
}

FileSource::~FileSource() { std::fclose(file_); }

Result<std::size_t> FileSource::read(std::span<std::uint8_t> out) {
  const std::size_t n = std::fread(out.data(), 1, out.size(), file_);
  if (n < out.size() && std::ferror(file_)) return make_error(name_ + ": read error (" + std::strerror(errno) + ")");
  return n;
}

}  // namespace gpubridge
