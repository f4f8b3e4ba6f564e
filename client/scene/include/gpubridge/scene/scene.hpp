#pragma once
// JSON scene files (docs/scene-format.md): a framebuffer, a clear, textures and draws of
// screen-space triangles, converted through the host geometry pipeline into a typed command
// stream (register frames + uploads) that any backend can execute.
//
// Two steps, usable separately:
//   read_scene_file / parse_scene   JSON → Scene (validated; errors name the file, the JSON path
//                                   and the problem: "scene.json: draws[2].vertices[7].x: ...")
//   build_commands                  Scene → memory layout + CommandStream
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/geometry/encode.hpp"
#include "gpubridge/geometry/pipeline.hpp"
#include "gpubridge/protocol/command_stream.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::scene {

// Bounds checked before anything is allocated or converted.
struct Limits {
  std::uint64_t max_file_bytes = 64u << 20;
  std::size_t max_textures = 256;
  std::size_t max_draws = 65536;
  std::size_t max_vertices = 1u << 22;  // over all draws
  double max_abs_xy = 1e7;              // |x|, |y| in pixels (the pipeline clips to the 12.4 range)
  double min_w = 1e-6, max_w = 1e6;
};

struct Texture {
  std::string name;
  Image image;  // RGBA8888, width/height powers of two 8..1024
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;  // stored format on the device
  protocol::Wrap wrap_s = protocol::Wrap::Repeat;
  protocol::Wrap wrap_t = protocol::Wrap::Repeat;
  bool bilinear = false;
};

struct Draw {
  geometry::RenderState state;             // state.textured is set when `texture` is
  std::optional<std::size_t> texture;      // index into Scene::textures
  std::optional<protocol::Wrap> wrap_s, wrap_t;  // override the texture's addressing
  std::optional<bool> bilinear;
  geometry::CullMode cull = geometry::CullMode::None;
  std::optional<std::array<unsigned, 4>> scissor;  // x0, y0, x1, y1 (exclusive ends)
  std::vector<geometry::ScreenVertex> vertices;    // triangle list: 3 per triangle
};

struct Scene {
  std::string name = "scene";  // file name used in error messages
  unsigned width = 320, height = 240;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  bool depth_buffer = false;   // allocate and clear a Z buffer (implied by any depth test/write)
  geometry::Vec4 clear_color{0, 0, 0, 1};
  double clear_depth = 1.0;
  std::vector<Texture> textures;
  std::vector<Draw> draws;
};

// Parses scene JSON. Relative texture paths resolve against base_dir.
Result<Scene> parse_scene(std::string_view json_text, std::string_view name_for_errors,
                          const std::filesystem::path& base_dir, const Limits& limits = {});
Result<Scene> read_scene_file(const std::filesystem::path& path, const Limits& limits = {});

// Where everything lives in video memory. Regions are allocated from address 0 upwards, each
// aligned to 256 bytes: colour buffer, depth buffer (if any), textures in the file's order.
struct MemoryLayout {
  std::uint32_t color = 0;
  std::optional<std::uint32_t> depth;
  std::vector<std::uint32_t> textures;  // parallel to Scene::textures
  std::uint64_t end = 0;                // first byte after the last region
};
inline constexpr std::uint32_t kRegionAlignment = 256;
Result<MemoryLayout> plan_memory(const Scene& scene, std::uint64_t vram_bytes);

struct BuildOptions {
  std::uint64_t vram_bytes = 8u << 20;  // the simulator's default VRAM
};

struct BuiltScene {
  protocol::CommandStream stream;  // ends with the FB_DISPLAY write that scans out the frame
  MemoryLayout layout;
  geometry::PipelineStats stats;   // summed over all draws
  unsigned width = 0, height = 0;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
};
// Converts a parsed scene: setup (FB_FORMAT, FB_DRAW, FB_Z, SCISSOR, clears), texture uploads,
// then per draw its state and triangles, and finally the swap.
Result<BuiltScene> build_commands(const Scene& scene, const BuildOptions& options = {});

// read_scene_file + build_commands.
Result<BuiltScene> load_scene(const std::filesystem::path& path, const BuildOptions& options = {},
                              const Limits& limits = {});

}  // namespace gpubridge::scene
