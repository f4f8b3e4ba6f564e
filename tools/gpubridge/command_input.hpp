#pragma once
// What `gpubridge render` and `gpubridge trace` read: a trace (text or binary) or a JSON scene file,
// whose command stream is built by the scene loader (docs/scene-format.md, "Command stream").
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gpubridge/common/trace_files.hpp"
#include "gpubridge/protocol/trace.hpp"
#include "gpubridge/scene/scene.hpp"

namespace gpubridge::cli {

// Loads `input`; `kind` becomes "scene" or "trace". vram_bytes: the device memory a scene's
// buffers and textures are laid out in.
inline Result<protocol::CommandStream> load_commands(const std::string& input, std::uint64_t vram_bytes,
                                                     std::string& kind) {
  const std::filesystem::path p(input);
  if (!std::filesystem::exists(p)) return make_error(input + ": no such file");
  if (p.extension() == ".json") {
    kind = "scene";
    scene::BuildOptions bo;
    bo.vram_bytes = vram_bytes;
    auto built = scene::load_scene(p, bo);
    if (!built) return built.error();
    return std::move(built->stream);
  }
  kind = "trace";
  return load_trace(p);
}

// True for a binary trace whose metadata says "device_kind": "dmc1" (a recorded DMC-1 session,
// read by dmc1::load_stream); only its header and metadata are read.
inline bool is_dmc1_binary_trace(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<std::uint8_t> head(protocol::kTraceHeaderBytes + protocol::kMaxTraceJson);
  in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (!protocol::looks_like_binary_trace(head)) return false;
  const auto kind = protocol::binary_trace_device_kind(head, path);
  return kind && *kind == protocol::DeviceKind::Dmc1;
}

}  // namespace gpubridge::cli
