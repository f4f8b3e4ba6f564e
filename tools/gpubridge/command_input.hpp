#pragma once
// What `gpubridge render` and `gpubridge trace` read: a trace (text or binary) or a JSON scene file,
// whose command stream is built by the scene loader (docs/scene-format.md, "Command stream").
#include <cstdint>
#include <filesystem>
#include <string>

#include "gpubridge/common/trace_files.hpp"
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

}  // namespace gpubridge::cli
