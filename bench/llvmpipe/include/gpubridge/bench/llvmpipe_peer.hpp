#pragma once
// Mesa llvmpipe as a peer of the simulator in `gpubridge bench accuracy`: the same triangles,
// pre-snapped to 1/16 px, rendered through OpenGL 3.3 core on an EGL surfaceless context into a
// framebuffer object (reference sheet rasterization-accuracy.md, section 5 and appendix).
//
// Coordinates are passed through unchanged (no y flip): Mesa's FBO row r is window y in [r, r+1)
// and its top-left rule then matches the device's y-down rule. Colour is interpolated
// `noperspective` (the device's Gouraud is screen-linear), u/v perspective-correct, depth linear.
//
// Measured as its best users would run it (issue 17): one GL program per output, each with only the
// varyings and state it needs, all linked once in create(); each program has its own vertex buffer
// holding only the attributes it reads, uploaded by set_vertices() outside any timed region.
//   Color            Gouraud: position (x, y, z) + RGBA8 colour, one noperspective vec4 varying
//   TextureDecal     position (x, y, z, w) + u/v, one perspective vec2 varying, a sampler
//   TexelCoordinates the same inputs, writes u * W, v * H to a float target (error pass only)
//   FlatColor        position (x, y, z, w) only, the colour a uniform (the error pass's hit counts)
//
// LP_NUM_THREADS is read when llvmpipe creates its screen, so each thread count runs in its own
// child process (run_isolated) and only results cross the process boundary.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"

namespace gpubridge::bench {

struct GlVertex {
  float x = 0, y = 0;  // pixels, y down, already on the 1/16 grid
  float z = 0;         // depth in [0, 1]
  float w = 1;         // perspective divisor (> 0)
  float r = 1, g = 1, b = 1, a = 1;
  float u = 0, v = 0;  // texture widths / heights
};

// A GlVertex colour channel (a byte / 255) back to its byte: the RGBA8 vertex colour of the Gouraud
// program and of bench/llvmpipe/minimal_gl.c's vertex file.
inline std::uint8_t unorm8(float f) { return std::uint8_t(std::lround(std::clamp(f, 0.0f, 1.0f) * 255.0f)); }

struct GlDrawState {
  enum class Depth { Off, Less, LessEqual, Always } depth = Depth::Off;  // Always: test on, every fragment writes
  enum class Blend { Off, Alpha, Add } blend = Blend::Off;
  enum class Output { Color, TextureDecal, TexelCoordinates, FlatColor } output = Output::Color;
  bool clear = true;
  float flat_rgba[4] = {1, 1, 1, 1};  // Output::FlatColor only
};

class LlvmpipePeer {
 public:
  // Creates the EGL surfaceless context and the framebuffer objects. Errors say which step failed
  // (missing extension, no llvmpipe renderer, incomplete FBO).
  static Result<std::unique_ptr<LlvmpipePeer>> create(unsigned width, unsigned height);
  ~LlvmpipePeer();
  LlvmpipePeer(const LlvmpipePeer&) = delete;
  LlvmpipePeer& operator=(const LlvmpipePeer&) = delete;

  const std::string& renderer() const { return renderer_; }
  // Binds an RGBA8 texture (rows top first), repeat addressing.
  void set_texture(std::span<const std::uint8_t> rgba, unsigned width, unsigned height, bool bilinear);
  // Stores the triangle list (3 vertices per triangle) in the vertex buffer of the program that
  // draws `output`, packed to the attributes that program reads.
  void set_vertices(std::span<const GlVertex> vertices, GlDrawState::Output output);
  // One frame with the program of state.output and the vertices last given for it: optional clear
  // (colour 0, depth 1), one glDrawArrays, glFinish.
  void render(const GlDrawState& state);
  // Read-back of the last frame, rows top first: RGBA8 colour, 24-bit depth, texel coordinates
  // (u * W, v * H per pixel, from the float target of Output::TexelCoordinates).
  std::vector<std::uint8_t> read_color();
  std::vector<std::uint32_t> read_depth24();
  std::vector<float> read_texel_coordinates();

 private:
  struct Gl;
  explicit LlvmpipePeer(std::unique_ptr<Gl> gl);
  std::unique_ptr<Gl> gl_;
  std::string renderer_;
};

// Runs `work` in a forked child with LP_NUM_THREADS = lp_threads and returns the text it produced
// (or the child's error message). Keeps llvmpipe's thread pools and JIT state out of the caller.
Result<std::string> run_isolated(unsigned lp_threads, const std::function<Result<std::string>()>& work);

}  // namespace gpubridge::bench
