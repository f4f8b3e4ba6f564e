#pragma once
// Draws the frame texture into a rectangle of the window and the overlay panel over it, with an
// OpenGL 3.3 core context (Mesa llvmpipe under Xvfb is enough). Frames are expanded to RGBA8888 on
// the CPU (the same bit-replication the screenshots use), so what is drawn equals what is saved.
#include <cstdint>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/viewer/layout.hpp"

namespace gpubridge::viewer {

class GlRenderer {
 public:
  // Needs a current GL 3.3 core context.
  static Result<GlRenderer> create();
  GlRenderer(GlRenderer&&) noexcept;
  GlRenderer& operator=(GlRenderer&&) noexcept;
  GlRenderer(const GlRenderer&) = delete;
  GlRenderer& operator=(const GlRenderer&) = delete;
  ~GlRenderer();

  void upload_frame(const Image& rgba);
  void upload_overlay(const Image& rgba);  // empty image = no overlay
  // Clears the window (fb_w x fb_h framebuffer pixels), draws the frame (if any was uploaded)
  // into `frame` and the overlay at the top-left corner.
  void draw(int fb_w, int fb_h, const Rect& frame, bool flip, bool with_overlay);
  // The back buffer as an image (rows top to bottom). Call after draw(), before swapping.
  Image read_back_buffer(int fb_w, int fb_h) const;

 private:
  GlRenderer() = default;
  void release();
  void draw_quad(int fb_w, int fb_h, const Rect& r, unsigned texture, bool flip);

  unsigned program_ = 0, vao_ = 0;
  unsigned frame_tex_ = 0, overlay_tex_ = 0;
  int loc_rect_ = -1, loc_flip_ = -1, loc_tex_ = -1;
  unsigned frame_w_ = 0, frame_h_ = 0, overlay_w_ = 0, overlay_h_ = 0;
};

}  // namespace gpubridge::viewer
