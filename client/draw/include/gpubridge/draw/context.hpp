#pragma once
// The drawing API: state, textures, indexed triangle lists with transforms and clipping, clears,
// swaps — on any CommandSink (simulator, board, daemon, recorder).
//
//   draw::BackendSink sink(simulator);
//   auto ctx = draw::Context::create(sink, {.width = 320, .height = 240});
//   auto tex = ctx->load_texture("bricks.png", {.format = protocol::PixelFormat::RGB565});
//   ctx->clear({0, 0, 0, 1});
//   ctx->clear_depth(1.0);
//   ctx->state().z_test = ctx->state().z_write = true;
//   ctx->set_transform(projection * view * model);
//   if (auto r = ctx->bind_texture(*tex); !r) return r;
//   ctx->draw_indexed(cube_vertices, cube_indices);
//   ctx->swap();
//   ctx->release_texture(*tex);  // when no longer needed (see below)
//
// Video memory (vram_allocator.hpp: address-ordered first-fit, 256-byte aligned) holds the
// colour buffers (two when double-buffered) and the depth buffer from address 0 up, for the
// Context's lifetime, then the textures. A texture lives until release_texture() or the end of
// the Context; its block is then reused, so a long-running client can stream frames or load
// levels without running out. With no releases the layout is the same as the original bump
// allocator's (buffers, then textures in creation order).
//
// Texture handles are plain values (copy them freely); each carries an id that the Context
// checks against its own record of the texture (address, size, format), which is what draws and
// updates use, so a handle edited by hand cannot point a draw at the wrong memory. Releasing one:
//   - frees its block at once: commands already issued that use it are sent before any later
//     upload can overwrite that memory (uploads and register writes stay in order);
//   - unbinds it if it is the bound texture (later draws are untextured until the next bind);
//   - makes every copy of the handle stale: bind_texture() and update_texture() reject it with
//     an error naming the texture, and releasing it again does nothing (returns false).
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <vector>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/draw/sink.hpp"
#include "gpubridge/draw/vram_allocator.hpp"
#include "gpubridge/geometry/encode.hpp"
#include "gpubridge/geometry/math.hpp"
#include "gpubridge/geometry/pipeline.hpp"

namespace gpubridge::draw {

struct ContextOptions {
  unsigned width = 640, height = 480;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  bool depth_buffer = true;
  bool double_buffer = true;
  std::size_t batch_frames = 8192;  // pending register writes sent to the sink in one go
  // swap() returns once at most this many swapped frames are still unexecuted (a remote daemon:
  // pipelined fences, no round trip per frame; 0 = no pacing: only the socket buffers bound how far
  // the program runs ahead of the device). Costs no memory in the program: the frames in flight
  // are in the socket buffers.
  unsigned frames_in_flight = 4;
  // Triangles that cannot cover a pixel of the framebuffer and scissor after snapping (wholly
  // off-screen, geometry::covers_no_pixel) are not sent: the device would draw nothing for them,
  // so the frames are the same with fewer bytes (docs/protocol.md 16.7). false sends them all,
  // e.g. to exercise a device's own rejection; PipelineStats::outside counts those skipped.
  bool skip_invisible = true;
};

// A vertex of an indexed mesh, in model space.
struct Vertex {
  geometry::Vec3 position;
  geometry::Vec4 color{1, 1, 1, 1};
  geometry::Vec2 uv;

  Vertex() = default;
  Vertex(geometry::Vec3 p, geometry::Vec4 c = {1, 1, 1, 1}, geometry::Vec2 t = {}) : position(p), color(c), uv(t) {}
};

struct TextureOptions {
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  protocol::Wrap wrap_s = protocol::Wrap::Repeat;
  protocol::Wrap wrap_t = protocol::Wrap::Repeat;
  bool bilinear = false;
};

struct Texture {
  std::uint32_t address = 0;
  geometry::TextureFormat format;
  std::uint64_t id = 0;  // assigned by create_texture (never reused); 0 = no texture
};

class Context {
 public:
  // Places the buffers and sets up FB_FORMAT, FB_DRAW, FB_Z, SCISSOR. Errors: bad size, not
  // enough video memory, or the sink's error.
  static Result<Context> create(CommandSink& sink, const ContextOptions& options = {});

  // --- state (applied to the following draws) ---
  // Everything in TRI_MODE except TEXTURED, which follows the bound texture.
  geometry::RenderState& state() { return state_; }
  void set_cull(geometry::CullMode mode, geometry::FrontFace front = geometry::FrontFace::CounterClockwise);
  // Model-view-projection matrix (clip space as in geometry/math.hpp).
  void set_transform(const geometry::Mat4& mvp) { mvp_ = mvp; }
  // Defaults to the whole framebuffer.
  void set_viewport(const geometry::Viewport& vp) { viewport_ = vp; }
  Result<void> set_scissor(unsigned x0, unsigned y0, unsigned x1, unsigned y1);
  void reset_scissor();

  // --- textures ---
  // Converts the image to the board format and uploads it. Sizes: powers of two 8..1024.
  Result<Texture> create_texture(const Image& image, const TextureOptions& options = {});
  Result<Texture> load_texture(const std::filesystem::path& png, const TextureOptions& options = {});
  // Re-uploads a texture's contents in place (same size; converted to the texture's format),
  // e.g. one video frame after another. Draws issued before the call sample the old contents.
  Result<void> update_texture(const Texture& texture, const Image& image);
  // Frees the texture's video memory and clears the handle (see the top of this file). Returns
  // false when the handle was already released (or empty): nothing happens then.
  bool release_texture(Texture& texture);
  // Following draws sample this texture. A released, edited or foreign handle is an error and
  // leaves the binding as it was.
  Result<void> bind_texture(const Texture& texture);
  // Following draws are untextured.
  void unbind_texture() { texture_.reset(); }

  // --- drawing ---
  Result<void> clear(geometry::Vec4 color);
  Result<void> clear_depth(double z = 1.0);
  // Indexed triangle list: every 3 indices form a triangle. Vertices are transformed once each.
  Result<void> draw_indexed(std::span<const Vertex> vertices, std::span<const std::uint32_t> indices);
  // Screen-space triangle list (pixels, y down; w for perspective-correct attributes). Each vertex
  // is snapped from the x, y given, whatever its w (docs/protocol.md 16.2).
  Result<void> draw_screen(std::span<const geometry::ScreenVertex> vertices);
  // Shows the back buffer (FB_DISPLAY) and, double-buffered, starts drawing into the other one.
  // Paced by ContextOptions::frames_in_flight.
  Result<void> swap();
  // Sends pending commands and waits until the device has executed them.
  Result<void> flush();
  // Reads the displayed buffer back (after swap) as an RGBA image.
  Result<Image> read_display();

  const geometry::PipelineStats& stats() const { return stats_; }
  // Video memory use (buffers and live textures), e.g. to show how much room is left.
  const VramAllocator& video_memory() const { return vram_; }
  std::size_t live_textures() const { return textures_.size(); }
  unsigned width() const { return options_.width; }
  unsigned height() const { return options_.height; }
  std::uint32_t back_buffer() const { return color_[back_]; }
  std::uint32_t front_buffer() const { return color_[1 - back_]; }

 private:
  Context(CommandSink& sink, const ContextOptions& options)
      : sink_(&sink), options_(options), vram_(sink.vram_bytes()) {}
  Result<std::uint32_t> allocate(std::uint64_t bytes, const char* what);
  // The context's record of a live texture, when the handle matches it exactly.
  const Texture* live(const Texture& texture) const;
  void write(protocol::Reg reg, std::uint64_t data);
  Result<void> send_pending();
  Result<void> apply_state(geometry::PipelineOptions& opt);
  // Queues the device triangles the pipeline left in scratch_ for the triangle at first_index
  // (r: the pipeline's result for it).
  Result<void> emit(const Result<void>& r, const geometry::PipelineOptions& opt, std::size_t first_index);

  CommandSink* sink_;
  ContextOptions options_;
  VramAllocator vram_;
  std::map<std::uint64_t, Texture> textures_;  // live textures by id
  std::uint64_t next_texture_id_ = 1;
  std::uint32_t color_[2] = {0, 0};
  int back_ = 0;
  std::optional<std::uint32_t> depth_;
  geometry::RenderState state_;
  geometry::CullMode cull_ = geometry::CullMode::None;
  geometry::FrontFace front_ = geometry::FrontFace::CounterClockwise;
  geometry::Mat4 mvp_ = geometry::identity();
  std::optional<geometry::Viewport> viewport_;
  std::optional<Texture> texture_;
  std::uint64_t scissor_ = 0;
  geometry::PixelRect scissor_rect_;  // scissor_ as a rectangle
  // Last values written, to skip redundant register writes.
  std::optional<std::uint64_t> sent_tri_mode_, sent_tex_base_, sent_tex_fmt_;
  std::vector<protocol::Frame> pending_;
  std::vector<std::uint8_t> wire_;
  std::vector<geometry::DeviceTriangle> scratch_;
  std::vector<geometry::Vertex> transformed_;
  geometry::PipelineStats stats_;
};

}  // namespace gpubridge::draw
