// Text-trace reader: lines → CommandStream. Consecutive register lines form one WRITE_FRAMES
// batch; any other command, `.batch`, or the per-message frame limit ends the batch.
#include <algorithm>

#include "gpubridge/protocol/text_trace.hpp"
#include "gpubridge/protocol/trace.hpp"
#include "text_trace_internal.hpp"

namespace gpubridge::protocol {
namespace {

using text::LineError;
using text::Token;

constexpr std::string_view kDirectives = ".upload, .mem, .fence, .read, .readback, .batch, .meta";

class TextTraceReader {
 public:
  TextTraceReader(std::string_view file, const AssetLoader& loader) : file_(file), loader_(loader) {}

  Result<CommandStream> run(std::string_view text) {
    std::size_t line_no = 0;
    std::size_t pos = 0;
    while (pos <= text.size()) {
      const std::size_t nl = text.find('\n', pos);
      std::string_view line = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
      ++line_no;
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      if (auto e = parse_line(line)) return make_error(location(line_no, e->column) + e->message);
      if (nl == std::string_view::npos) break;
      pos = nl + 1;
    }
    flush();
    return std::move(stream_);
  }

 private:
  std::string location(std::size_t line, std::size_t col) const {
    return std::string(file_) + ":" + std::to_string(line) + ":" + std::to_string(col) + ": ";
  }

  void flush() {
    if (!frames_.bytes.empty()) stream_.commands.push_back(TimedCommand{0, std::move(frames_)});
    frames_ = FramesCmd{};
  }
  void emit(Command c) {
    flush();
    stream_.commands.push_back(TimedCommand{0, std::move(c)});
  }

  std::optional<LineError> parse_line(std::string_view line) {
    // `.meta` takes the rest of the line verbatim: JSON strings may contain '#'.
    const auto first = line.find_first_not_of(" \t");
    if (first != std::string_view::npos && line.substr(first, 5) == ".meta" &&
        (line.size() == first + 5 || line[first + 5] == ' ' || line[first + 5] == '\t'))
      return meta(line.substr(first + 5), first + 1);
    if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    const auto tokens = text::tokenize(line);
    if (tokens.empty()) return std::nullopt;
    if (tokens[0].text[0] == '.') return directive(tokens);
    Frame f;
    if (auto e = text::parse_register_tokens(tokens, f)) return e;
    if (frames_.size() >= kMaxFramesPerBatch) flush();
    frames_.push(f);
    return std::nullopt;
  }

  std::optional<LineError> meta(std::string_view rest, std::size_t column) {
    if (have_meta_) return LineError{column, ".meta appears twice; merge the metadata into one JSON object"};
    const auto start = rest.find_first_not_of(" \t");
    const std::string json(start == std::string_view::npos ? std::string_view() : rest.substr(start));
    if (auto problem = json_object_problem(json); !problem.empty())
      return LineError{column, ".meta value " + problem + "; write a one-line JSON object"};
    // Text traces hold spigpu register writes only; a DMC-1 trace is binary (docs/protocol.md 18.1).
    const auto kind = trace_metadata_device_kind(json);
    if (!kind) return LineError{column, ".meta " + kind.error().message + "; remove it or write \"spigpu\""};
    if (*kind != DeviceKind::Spigpu)
      return LineError{column, ".meta says device_kind \"" + std::string(device_kind_info(*kind).name) +
                                   "\", but a text trace holds spigpu register writes (" +
                                   std::string(device_kind_info(*kind).label) +
                                   " traces are binary only); remove \"device_kind\" or write \"spigpu\""};
    stream_.metadata_json = json;
    have_meta_ = true;
    return std::nullopt;
  }

  static std::optional<LineError> arity(std::span<const Token> t, std::size_t min, std::size_t max, const char* usage) {
    if (t.size() < min || t.size() > max) {
      const std::size_t col = t.size() > max ? t[max].column : t.back().column + t.back().text.size();
      return LineError{col, std::string("usage: ") + usage};
    }
    return std::nullopt;
  }

  static std::optional<LineError> number(const Token& t, std::uint64_t max, const char* what, std::uint64_t& out) {
    auto n = text::parse_u64(t.text);
    if (!n) return LineError{t.column, "'" + text::shown(t.text) + "' is not a " + what + "; write decimal or 0x hex"};
    if (*n > max)
      return LineError{t.column, std::string(what) + " " + text::shown(t.text) + " exceeds " + std::to_string(max)};
    out = *n;
    return std::nullopt;
  }

  std::optional<LineError> add_upload(const Token& where, std::uint32_t address, std::vector<std::uint8_t> data) {
    if (data.empty()) return LineError{where.column, "the upload has no bytes; give at least one"};
    if (std::uint64_t{address} + data.size() > (std::uint64_t{1} << 32))
      return LineError{where.column, "an upload of " + std::to_string(data.size()) + " bytes at address " +
                                         std::to_string(address) + " runs past the 4 GiB address space"};
    // One UPLOAD message carries at most kMaxUploadBytes; larger data becomes consecutive uploads.
    if (data.size() <= kMaxUploadBytes) {
      emit(UploadCmd{address, std::move(data)});
      return std::nullopt;
    }
    for (std::size_t off = 0; off < data.size(); off += kMaxUploadBytes) {
      const auto first = data.begin() + static_cast<std::ptrdiff_t>(off);
      const auto n = static_cast<std::ptrdiff_t>(std::min<std::size_t>(kMaxUploadBytes, data.size() - off));
      emit(UploadCmd{static_cast<std::uint32_t>(address + off), {first, first + n}});
    }
    return std::nullopt;
  }

  std::optional<LineError> directive(std::span<const Token> t) {
    const std::string_view d = t[0].text;
    std::uint64_t a = 0, b = 0;
    if (text::iequals(d, ".batch")) {
      if (auto e = arity(t, 1, 1, ".batch")) return e;
      flush();
      return std::nullopt;
    }
    if (text::iequals(d, ".fence")) {
      if (auto e = arity(t, 2, 2, ".fence ID")) return e;
      if (auto e = number(t[1], ~0ull, "fence id", a)) return e;
      emit(FenceCmd{a});
      return std::nullopt;
    }
    if (text::iequals(d, ".read")) {
      if (auto e = arity(t, 2, 2, ".read NAME (or .read 0xIDX)")) return e;
      if (const RegisterDesc* r = find_register(t[1].text)) {
        emit(ReadRegCmd{r->index});
        return std::nullopt;
      }
      auto idx = text::parse_u64(t[1].text);
      if (!idx || *idx > 0x7F)
        return LineError{t[1].column, "unknown register '" + text::shown(t[1].text) +
                                          "'; run `gpubridge regs` for the names, or give an index 0x00..0x7F"};
      emit(ReadRegCmd{static_cast<std::uint8_t>(*idx)});
      return std::nullopt;
    }
    if (text::iequals(d, ".readback")) {
      if (auto e = arity(t, 3, 3, ".readback ADDR LENGTH")) return e;
      if (auto e = number(t[1], 0xFFFF'FFFFull, "address", a)) return e;
      if (auto e = number(t[2], kMaxReadbackBytes, "readback length", b)) return e;
      if (b == 0) return LineError{t[2].column, "readback length 0; read at least 1 byte"};
      emit(ReadbackCmd{static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b)});
      return std::nullopt;
    }
    if (text::iequals(d, ".mem")) {
      if (auto e = arity(t, 3, ~std::size_t{0}, ".mem ADDR HEXBYTES...")) return e;
      if (auto e = number(t[1], 0xFFFF'FFFFull, "address", a)) return e;
      std::vector<std::uint8_t> data;
      for (std::size_t i = 2; i < t.size(); ++i) {
        auto bytes = parse_hex_bytes(t[i].text);
        if (!bytes)
          return LineError{t[i].column, "'" + text::shown(t[i].text) +
                                            "' is not hex bytes; write pairs of hex digits (00..ff)"};
        data.insert(data.end(), bytes->begin(), bytes->end());
      }
      return add_upload(t[1], static_cast<std::uint32_t>(a), std::move(data));
    }
    if (text::iequals(d, ".upload")) {
      if (auto e = arity(t, 4, 5, ".upload ADDR png FILE [RGBA8888|RGB565|RGBA2222]  or  .upload ADDR hex FILE"))
        return e;
      if (auto e = number(t[1], 0xFFFF'FFFFull, "address", a)) return e;
      TraceAsset asset;
      asset.path = std::string(t[3].text);
      if (text::iequals(t[2].text, "png")) {
        asset.kind = TraceAsset::Kind::Png;
        if (t.size() == 5) {
          auto f = parse_pixel_format(t[4].text);
          if (!f)
            return LineError{t[4].column, "'" + text::shown(t[4].text) +
                                              "' is not a pixel format; use RGBA8888, RGB565 or RGBA2222"};
          asset.format = *f;
        }
      } else if (text::iequals(t[2].text, "hex")) {
        asset.kind = TraceAsset::Kind::Hex;
        if (t.size() == 5) return LineError{t[4].column, "a hex upload takes no format; the file holds device bytes"};
      } else {
        return LineError{t[2].column, "'" + text::shown(t[2].text) + "' is not an upload kind; use png or hex"};
      }
      if (!loader_)
        return LineError{t[3].column, "this reader cannot open files (no loader); convert with `gpubridge trace`"};
      auto bytes = loader_(asset);
      if (!bytes) return LineError{t[3].column, bytes.error().message};
      return add_upload(t[1], static_cast<std::uint32_t>(a), std::move(bytes).value());
    }
    return LineError{t[0].column, "unknown directive '" + std::string(d) + "'; directives are " + std::string(kDirectives)};
  }

  std::string_view file_;
  const AssetLoader& loader_;
  CommandStream stream_;
  FramesCmd frames_;
  bool have_meta_ = false;
};

}  // namespace

Result<CommandStream> parse_text_trace(std::string_view text, std::string_view file_name, const AssetLoader& loader) {
  return TextTraceReader(file_name, loader).run(text);
}

}  // namespace gpubridge::protocol
