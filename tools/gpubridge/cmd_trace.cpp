// `gpubridge trace`: convert traces between the binary (.gbt) and text (.trace/.txt) forms, and
// list their contents. Parsing and formatting live in protocol/; files in common/trace_files.
// DMC-1 recordings and streams (docs/dmc1.md) convert to DMC-1 stream files and list their words.
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "command_input.hpp"
#include "gpubridge/dmc1/command.hpp"
#include "gpubridge/dmc1/stream.hpp"
#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/text_trace.hpp"
#include "gpubridge/sim/options.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::cli {
namespace {

using protocol::CommandStream;
// Scene files are laid out in the simulator's default video memory (as `gpubridge render` does).
const std::uint64_t kSceneVramBytes = sim::DeviceOptions{}.vram_bytes;

struct TraceCounts {
  std::size_t batches = 0, frames = 0, uploads = 0, upload_bytes = 0, fences = 0, reads = 0, readbacks = 0;
};
TraceCounts count(const CommandStream& s) {
  TraceCounts c;
  for (const auto& tc : s.commands) {
    if (const auto* f = std::get_if<protocol::FramesCmd>(&tc.command)) ++c.batches, c.frames += f->size();
    else if (const auto* u = std::get_if<protocol::UploadCmd>(&tc.command)) ++c.uploads, c.upload_bytes += u->data.size();
    else if (std::holds_alternative<protocol::FenceCmd>(tc.command)) ++c.fences;
    else if (std::holds_alternative<protocol::ReadRegCmd>(tc.command)) ++c.reads;
    else ++c.readbacks;
  }
  return c;
}
nlohmann::json counts_json(const TraceCounts& c) {
  return {{"write_batches", c.batches}, {"frames", c.frames}, {"uploads", c.uploads}, {"upload_bytes", c.upload_bytes},
          {"fences", c.fences},         {"reads", c.reads},   {"readbacks", c.readbacks}};
}

std::optional<TraceFormat> parse_format_name(const std::string& s) {
  if (s == "text") return TraceFormat::Text;
  if (s == "binary") return TraceFormat::Binary;
  return std::nullopt;
}

std::string hex32(std::uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%08X", v);
  return b;
}
std::string hex64(std::uint64_t v) {
  char b[24];
  std::snprintf(b, sizeof b, "0x%016llX", static_cast<unsigned long long>(v));
  return b;
}

// ------------------------------------------------------------------------------ DMC-1
// A DMC-1 recording (a binary trace whose metadata says "device_kind": "dmc1") or stream file.
bool is_dmc1_input(const std::string& in) { return dmc1::stream_format_for_path(in) || is_dmc1_binary_trace(in); }

std::string dmc1_source(const dmc1::LoadedStream& s) {
  return s.binary_trace ? "recording" : std::string(dmc1::to_string(s.format));
}

std::size_t dmc1_frames(std::span<const std::uint64_t> words) {
  std::size_t eocs = 0;
  for (const auto w : words) eocs += dmc1::kind_of(w) == dmc1::CommandKind::EndOfColumn;
  return eocs / dmc1::kColumns;
}

// Its command words as a stream file: .dmc1 (text) or .nfo (tinygpus lines). A DMC-1 recording has
// only command words and fences; the fences are left out (a stream file has none).
int run_convert_dmc1(const GlobalOptions& g, const std::string& in, const std::string& out, const std::string& to) {
  const auto format = dmc1::stream_format_for_path(out);
  if (!to.empty() || !format) {
    std::fprintf(stderr,
                 "gpubridge trace convert: %s holds DMC-1 command words, which convert to a DMC-1 stream file: name "
                 "the output .dmc1 (text) or .nfo (tinygpus lines)%s\n",
                 in.c_str(), to.empty() ? "" : " instead of passing --to");
    return 2;
  }
  auto s = dmc1::load_stream(in);
  if (!s) {
    std::fprintf(stderr, "gpubridge trace convert: %s\n", s.error().message.c_str());
    return 1;
  }
  if (auto r = dmc1::save_stream(out, s->words, format); !r) {
    std::fprintf(stderr, "gpubridge trace convert: %s\n", r.error().message.c_str());
    return 1;
  }
  const auto frames = dmc1_frames(s->words);
  if (g.json) {
    nlohmann::json j{{"input", in},          {"output", out},
                     {"device_kind", "dmc1"}, {"source", dmc1_source(*s)},
                     {"format", std::string(dmc1::to_string(*format))}, {"command_words", s->words.size()},
                     {"frames", frames}};
    std::puts(json_text(j, 2).c_str());
  } else {
    std::printf("wrote %s (DMC-1 %s format, %zu command words, %zu frames)\n", out.c_str(),
                std::string(dmc1::to_string(*format)).c_str(), s->words.size(), frames);
  }
  return 0;
}

// Every command word decoded (the field table of `gpubridge regs --device dmc1`), frame ends marked.
int run_dump_dmc1(const GlobalOptions& g, const std::string& in) {
  auto s = dmc1::load_stream(in);
  if (!s) {
    std::fprintf(stderr, "gpubridge trace dump: %s\n", s.error().message.c_str());
    return 1;
  }
  const auto frames = dmc1_frames(s->words);
  if (g.json) {
    nlohmann::json words = nlohmann::json::array();
    for (std::size_t i = 0; i < s->words.size(); ++i)
      words.push_back({{"index", i}, {"word", hex64(s->words[i])}, {"text", dmc1::describe(s->words[i])}});
    nlohmann::json j{{"file", in},
                     {"device_kind", "dmc1"},
                     {"source", dmc1_source(*s)},
                     {"counts", {{"command_words", s->words.size()}, {"frames", frames}}},
                     {"words", words}};
    std::puts(json_text(j, 2).c_str());
    return 0;
  }
  std::printf("%s: DMC-1 %s\n", in.c_str(), s->binary_trace ? "recording" : "stream");
  std::size_t eocs = 0;
  for (std::size_t i = 0; i < s->words.size(); ++i) {
    std::printf("#%-6zu %s  %s\n", i, hex64(s->words[i]).c_str(), dmc1::describe(s->words[i]).c_str());
    if (dmc1::kind_of(s->words[i]) == dmc1::CommandKind::EndOfColumn && ++eocs % dmc1::kColumns == 0)
      std::printf("        -- end of frame %zu\n", eocs / dmc1::kColumns - 1);
  }
  std::printf("%zu command words: %zu frames\n", s->words.size(), frames);
  return 0;
}

// ------------------------------------------------------------------------------ spigpu
int run_convert(const GlobalOptions& g, const std::string& in, const std::string& out, const std::string& to) {
  if (is_dmc1_input(in)) return run_convert_dmc1(g, in, out, to);
  std::optional<TraceFormat> format;
  if (!to.empty()) {
    format = parse_format_name(to);
    if (!format) {
      std::fprintf(stderr, "gpubridge trace convert: --to %s is not a format; use text or binary\n", to.c_str());
      return 2;
    }
  } else if (!trace_format_for_path(out)) {
    std::fprintf(stderr,
                 "gpubridge trace convert: cannot tell the output format of %s; name it .gbt (binary) or "
                 ".trace/.txt (text), or pass --to text|binary\n",
                 out.c_str());
    return 2;
  }
  std::string kind;
  auto s = load_commands(in, kSceneVramBytes, kind);
  if (!s) {
    std::fprintf(stderr, "gpubridge trace convert: %s\n", s.error().message.c_str());
    return 1;
  }
  if (auto r = save_trace(out, *s, format); !r) {
    std::fprintf(stderr, "gpubridge trace convert: %s\n", r.error().message.c_str());
    return 1;
  }
  const auto c = count(*s);
  const bool binary = (format ? *format : *trace_format_for_path(out)) == TraceFormat::Binary;
  if (g.json) {
    nlohmann::json j{{"input", in}, {"output", out}, {"format", binary ? "binary" : "text"},
                     {"commands", s->commands.size()}, {"counts", counts_json(c)}};
    std::puts(json_text(j, 2).c_str());
  } else {
    std::printf("wrote %s (%s, %zu commands: %zu frames in %zu batches, %zu uploads, %zu fences)\n", out.c_str(),
                binary ? "binary" : "text", s->commands.size(), c.frames, c.batches, c.uploads, c.fences);
  }
  return 0;
}

nlohmann::json command_json(std::size_t i, const protocol::TimedCommand& tc) {
  using namespace protocol;
  nlohmann::json j{{"index", i}, {"timestamp_ns", tc.timestamp_ns},
                   {"type", std::string(to_string(message_type_of(tc.command)))}};
  if (const auto* f = std::get_if<FramesCmd>(&tc.command)) {
    auto frames = nlohmann::json::array();
    const auto v = f->view();
    for (std::size_t k = 0; k < v.size(); ++k) {
      const Frame fr = v[k];
      const RegisterDesc* r = find_register(fr.index);
      frames.push_back({{"index", fr.index},
                        {"register", r ? std::string(r->name) : std::string()},
                        {"data", hex64(fr.data)},
                        {"text", format_register_write(fr.index, fr.data)}});
    }
    j["frames"] = frames;
  } else if (const auto* u = std::get_if<UploadCmd>(&tc.command)) {
    j["address"] = u->address;
    j["length"] = u->data.size();
    j["crc32"] = hex32(crc32(u->data));
  } else if (const auto* fe = std::get_if<FenceCmd>(&tc.command)) {
    j["id"] = fe->id;
  } else if (const auto* r = std::get_if<ReadRegCmd>(&tc.command)) {
    j["register_index"] = r->index;
    const RegisterDesc* d = find_register(r->index);
    j["register"] = d ? std::string(d->name) : std::string();
  } else if (const auto* rb = std::get_if<ReadbackCmd>(&tc.command)) {
    j["address"] = rb->address;
    j["length"] = rb->length;
  }
  return j;
}

int run_dump(const GlobalOptions& g, const std::string& in) {
  if (is_dmc1_input(in)) return run_dump_dmc1(g, in);
  std::string kind;
  auto s = load_commands(in, kSceneVramBytes, kind);
  if (!s) {
    std::fprintf(stderr, "gpubridge trace dump: %s\n", s.error().message.c_str());
    return 1;
  }
  const auto c = count(*s);
  if (g.json) {
    nlohmann::json cmds = nlohmann::json::array();
    for (std::size_t i = 0; i < s->commands.size(); ++i) cmds.push_back(command_json(i, s->commands[i]));
    nlohmann::json j{{"file", in},
                     {"metadata", nlohmann::json::parse(s->metadata_json, nullptr, false)},
                     {"counts", counts_json(c)},
                     {"commands", cmds}};
    std::puts(json_text(j, 2).c_str());
    return 0;
  }
  std::printf("%s: metadata %s\n", in.c_str(), s->metadata_json.c_str());
  for (std::size_t i = 0; i < s->commands.size(); ++i) {
    const auto j = command_json(i, s->commands[i]);
    const std::string type = j["type"];
    std::printf("#%-5zu %12llu ns  %-12s", i, static_cast<unsigned long long>(s->commands[i].timestamp_ns), type.c_str());
    if (j.contains("frames")) {
      std::printf(" %zu frames\n", j["frames"].size());
      for (const auto& f : j["frames"]) std::printf("        %s\n", f["text"].get<std::string>().c_str());
    } else if (type == "UPLOAD") {
      std::printf(" %s, %zu bytes, crc32 %s\n", hex32(j["address"]).c_str(), j["length"].get<std::size_t>(),
                  j["crc32"].get<std::string>().c_str());
    } else if (type == "FENCE") {
      std::printf(" id %llu\n", static_cast<unsigned long long>(j["id"].get<std::uint64_t>()));
    } else if (type == "READ_REG") {
      std::printf(" %s (0x%02X)\n", j["register"].get<std::string>().c_str(), j["register_index"].get<unsigned>());
    } else {
      std::printf(" %s, %u bytes\n", hex32(j["address"]).c_str(), j["length"].get<unsigned>());
    }
  }
  std::printf("%zu commands: %zu frames in %zu batches, %zu uploads (%zu bytes), %zu fences, %zu reads, %zu readbacks\n",
              s->commands.size(), c.frames, c.batches, c.uploads, c.upload_bytes, c.fences, c.reads, c.readbacks);
  return 0;
}

}  // namespace

GPUBRIDGE_COMMAND("trace", 40, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  auto* trace = app.add_subcommand(
      "trace", "convert and inspect command traces (binary .gbt recordings and text .trace files; DMC-1 recordings and streams)");
  trace->require_subcommand(1);
  trace->footer(
      "Formats are chosen by extension: .gbt/.gbtrace = binary, .trace/.txt = text (docs/protocol.md, \"Traces\").\n"
      "Binary -> text -> binary is byte-identical except timestamps (text traces carry none).\n"
      "A DMC-1 recording (metadata \"device_kind\": \"dmc1\") or stream (.dmc1, .nfo) converts to a .dmc1 or .nfo "
      "stream file; dump lists its command words decoded (docs/dmc1.md).");

  struct ConvertArgs {
    std::string in, out, to;
  };
  auto conv = std::make_shared<ConvertArgs>();
  auto* convert = trace->add_subcommand(
      "convert", "convert a trace between the binary and text forms, or save a scene file's commands as a trace");
  convert->add_option("IN", conv->in,
                      "input trace (format detected from its content), a scene file (.json): its command stream, or a "
                      "DMC-1 recording or stream")
      ->required();
  convert->add_option("OUT", conv->out,
                      "output trace (.gbt/.gbtrace binary, .trace/.txt text); for DMC-1 input a stream file (.dmc1, .nfo)")
      ->required();
  convert->add_option("--to", conv->to, "output format when the extension does not say: text|binary");
  runners.emplace_back(convert, [&g, conv] { return run_convert(g, conv->in, conv->out, conv->to); });

  auto in = std::make_shared<std::string>();
  auto* dump = trace->add_subcommand("dump", "list a trace's commands (register writes by name; --json for tools)");
  dump->add_option("IN", *in, "trace file (binary or text), a scene file (.json), or a DMC-1 recording or stream")->required();
  runners.emplace_back(dump, [&g, in] { return run_dump(g, *in); });
});

}  // namespace gpubridge::cli
