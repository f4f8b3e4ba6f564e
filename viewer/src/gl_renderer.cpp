#include "gl_renderer.hpp"

// Linux GL: libGL (glvnd) exports every core entry point, so prototypes are enough; no loader.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <algorithm>
#include <string>
#include <utility>

namespace gpubridge::viewer {
namespace {

// A quad from gl_VertexID (no vertex buffers): u_rect is x0, y0, x1, y1 in clip space.
constexpr const char* kVertexShader = R"(#version 330 core
uniform vec4 u_rect;
uniform int u_flip;
out vec2 v_uv;
void main() {
  vec2 corner = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
  gl_Position = vec4(mix(u_rect.xy, u_rect.zw, corner), 0.0, 1.0);
  // Texture row 0 is the frame's top row; corner.y = 0 is the top of the rectangle.
  v_uv = vec2(corner.x, u_flip != 0 ? 1.0 - corner.y : corner.y);
}
)";

constexpr const char* kFragmentShader = R"(#version 330 core
uniform sampler2D u_tex;
in vec2 v_uv;
out vec4 o_color;
void main() { o_color = texture(u_tex, v_uv); }
)";

Result<GLuint> compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[1024] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    glDeleteShader(shader);
    return make_error(std::string("OpenGL shader compilation failed: ") + log);
  }
  return shader;
}

GLuint make_texture() {
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  // Nearest: frame pixels stay sharp squares (and integer scaling is exact).
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return tex;
}

void upload(GLuint tex, const Image& img, unsigned& w, unsigned& h) {
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (img.width != w || img.height != h) {
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, static_cast<GLsizei>(img.width), static_cast<GLsizei>(img.height), 0,
                 GL_RGBA, GL_UNSIGNED_BYTE, img.rgba.data());
    w = img.width;
    h = img.height;
  } else {
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, static_cast<GLsizei>(img.width), static_cast<GLsizei>(img.height),
                    GL_RGBA, GL_UNSIGNED_BYTE, img.rgba.data());
  }
}

}  // namespace

Result<GlRenderer> GlRenderer::create() {
  auto vs = compile(GL_VERTEX_SHADER, kVertexShader);
  if (!vs) return vs.error();
  auto fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  if (!fs) {
    glDeleteShader(*vs);
    return fs.error();
  }
  GlRenderer r;
  r.program_ = glCreateProgram();
  glAttachShader(r.program_, *vs);
  glAttachShader(r.program_, *fs);
  glLinkProgram(r.program_);
  glDeleteShader(*vs);
  glDeleteShader(*fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(r.program_, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[1024] = {};
    glGetProgramInfoLog(r.program_, sizeof log, nullptr, log);
    return make_error(std::string("OpenGL program link failed: ") + log);
  }
  r.loc_rect_ = glGetUniformLocation(r.program_, "u_rect");
  r.loc_flip_ = glGetUniformLocation(r.program_, "u_flip");
  r.loc_tex_ = glGetUniformLocation(r.program_, "u_tex");
  glGenVertexArrays(1, &r.vao_);
  r.frame_tex_ = make_texture();
  r.overlay_tex_ = make_texture();
  return r;
}

GlRenderer::GlRenderer(GlRenderer&& o) noexcept { *this = std::move(o); }

GlRenderer& GlRenderer::operator=(GlRenderer&& o) noexcept {
  if (this != &o) {
    release();
    program_ = std::exchange(o.program_, 0u);
    vao_ = std::exchange(o.vao_, 0u);
    frame_tex_ = std::exchange(o.frame_tex_, 0u);
    overlay_tex_ = std::exchange(o.overlay_tex_, 0u);
    loc_rect_ = o.loc_rect_;
    loc_flip_ = o.loc_flip_;
    loc_tex_ = o.loc_tex_;
    frame_w_ = std::exchange(o.frame_w_, 0u);
    frame_h_ = std::exchange(o.frame_h_, 0u);
    overlay_w_ = std::exchange(o.overlay_w_, 0u);
    overlay_h_ = std::exchange(o.overlay_h_, 0u);
  }
  return *this;
}

GlRenderer::~GlRenderer() { release(); }

void GlRenderer::release() {
  if (frame_tex_) glDeleteTextures(1, &frame_tex_);
  if (overlay_tex_) glDeleteTextures(1, &overlay_tex_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (program_) glDeleteProgram(program_);
  frame_tex_ = overlay_tex_ = vao_ = program_ = 0;
}

void GlRenderer::upload_frame(const Image& rgba) {
  if (rgba.width == 0 || rgba.height == 0) return;
  upload(frame_tex_, rgba, frame_w_, frame_h_);
}

void GlRenderer::upload_overlay(const Image& rgba) {
  if (rgba.width == 0 || rgba.height == 0) {
    overlay_w_ = overlay_h_ = 0;
    return;
  }
  upload(overlay_tex_, rgba, overlay_w_, overlay_h_);
}

void GlRenderer::draw_quad(int fb_w, int fb_h, const Rect& r, unsigned texture, bool flip) {
  // Window pixels (origin top-left) to clip space (origin centre, y up).
  const float x0 = 2.0f * static_cast<float>(r.x) / static_cast<float>(fb_w) - 1.0f;
  const float x1 = 2.0f * static_cast<float>(r.x + r.width) / static_cast<float>(fb_w) - 1.0f;
  const float y0 = 1.0f - 2.0f * static_cast<float>(r.y) / static_cast<float>(fb_h);
  const float y1 = 1.0f - 2.0f * static_cast<float>(r.y + r.height) / static_cast<float>(fb_h);
  glUniform4f(loc_rect_, x0, y0, x1, y1);
  glUniform1i(loc_flip_, flip ? 1 : 0);
  glBindTexture(GL_TEXTURE_2D, texture);
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
}

void GlRenderer::draw(int fb_w, int fb_h, const Rect& frame, bool flip, bool with_overlay) {
  glViewport(0, 0, fb_w, fb_h);
  glClearColor(0.08f, 0.08f, 0.09f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  if (fb_w <= 0 || fb_h <= 0) return;
  glUseProgram(program_);
  glBindVertexArray(vao_);
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(loc_tex_, 0);
  if (frame_w_ && frame.width > 0 && frame.height > 0) {
    glDisable(GL_BLEND);
    draw_quad(fb_w, fb_h, frame, frame_tex_, flip);
  }
  if (with_overlay && overlay_w_) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    draw_quad(fb_w, fb_h, Rect{0, 0, static_cast<int>(overlay_w_), static_cast<int>(overlay_h_)}, overlay_tex_,
              false);
    glDisable(GL_BLEND);
  }
}

Image GlRenderer::read_back_buffer(int fb_w, int fb_h) const {
  Image img;
  if (fb_w <= 0 || fb_h <= 0) return img;
  img.width = static_cast<unsigned>(fb_w);
  img.height = static_cast<unsigned>(fb_h);
  std::vector<std::uint8_t> bottom_up(std::size_t{img.width} * img.height * 4);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, fb_w, fb_h, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
  img.rgba.resize(bottom_up.size());
  const std::size_t row = std::size_t{img.width} * 4;
  for (unsigned y = 0; y < img.height; ++y) {  // GL rows are bottom to top
    std::copy_n(bottom_up.data() + (img.height - 1 - y) * row, row, img.rgba.data() + y * row);
  }
  // The window is opaque whatever alpha the frame carries (the default framebuffer may not even
  // store alpha): the grab is what a person sees.
  for (std::size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = 255;
  return img;
}

}  // namespace gpubridge::viewer
