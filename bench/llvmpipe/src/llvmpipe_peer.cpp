// EGL surfaceless + FBO rendering with Mesa llvmpipe (see llvmpipe_peer.hpp).
#define GL_GLEXT_PROTOTYPES 1
#include "gpubridge/bench/llvmpipe_peer.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>

namespace gpubridge::bench {

namespace {

// The vertex buffer layouts (only what each program reads; see llvmpipe_peer.hpp).
enum class Layout { Gouraud, Textured, Position };
constexpr int kLayouts = 3;
constexpr int kOutputs = 4;

struct GouraudVertex {
  float x, y, z;
  std::uint8_t rgba[4];  // normalised: exactly the r/255 of GlVertex
};
struct TexturedVertex {
  float x, y, z, w, u, v;
};
struct PositionVertex {
  float x, y, z, w;
};

Layout layout_of(GlDrawState::Output o) {
  switch (o) {
    case GlDrawState::Output::Color: return Layout::Gouraud;
    case GlDrawState::Output::TextureDecal:
    case GlDrawState::Output::TexelCoordinates: return Layout::Textured;
    case GlDrawState::Output::FlatColor: return Layout::Position;
  }
  return Layout::Gouraud;
}

}  // namespace

struct LlvmpipePeer::Gl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  unsigned width = 0, height = 0;
  GLuint fbo_rgba8 = 0, fbo_float = 0, color_rb = 0, float_rb = 0, depth_rb = 0;
  GLuint texture = 0;
  GLuint program[kOutputs] = {};  // by GlDrawState::Output
  GLint u_flat_color = -1, u_tex_size = -1;
  GLuint vao[kLayouts] = {}, vbo[kLayouts] = {};
  GLsizei vertex_count[kLayouts] = {};
  float tex_w = 1, tex_h = 1;

  ~Gl() {
    if (display == EGL_NO_DISPLAY) return;
    if (context != EGL_NO_CONTEXT) {
      glDeleteBuffers(kLayouts, vbo);
      glDeleteVertexArrays(kLayouts, vao);
      glDeleteTextures(1, &texture);
      for (GLuint p : program) glDeleteProgram(p);
      glDeleteFramebuffers(1, &fbo_rgba8);
      glDeleteFramebuffers(1, &fbo_float);
      GLuint rbs[3] = {color_rb, float_rb, depth_rb};
      glDeleteRenderbuffers(3, rbs);
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display, context);
    }
    eglTerminate(display);
  }
};

namespace {

// Positions arrive in pixels (y down, no flip: FBO row r is window y in [r, r + 1)), z in [0, 1].
// Gouraud and flat draws leave w at 1: noperspective colour and depth do not depend on it, and the
// Gouraud scenes' w is 1 anyway.
constexpr const char* kGouraudVertex = R"(#version 330 core
layout(location = 0) in vec3 pos;
layout(location = 1) in vec4 color;
uniform vec2 scale;                  // 2 / width, 2 / height
noperspective out vec4 v_color;      // the device's Gouraud is linear in screen space
void main() {
  gl_Position = vec4(pos.xy * scale - 1.0, 2.0 * pos.z - 1.0, 1.0);
  v_color = color;
}
)";
constexpr const char* kGouraudFragment = R"(#version 330 core
noperspective in vec4 v_color;
out vec4 frag;
void main() { frag = v_color; }
)";

constexpr const char* kTexturedVertex = R"(#version 330 core
layout(location = 0) in vec4 pos;    // x, y in pixels, z in [0, 1], w
layout(location = 1) in vec2 uv;
uniform vec2 scale;
out vec2 v_uv;                       // perspective-correct
void main() {
  gl_Position = vec4((pos.xy * scale - 1.0) * pos.w, (2.0 * pos.z - 1.0) * pos.w, pos.w);
  v_uv = uv;
}
)";
constexpr const char* kDecalFragment = R"(#version 330 core
in vec2 v_uv;
uniform sampler2D tex;
out vec4 frag;
void main() { frag = texture(tex, v_uv); }
)";
constexpr const char* kTexelFragment = R"(#version 330 core
in vec2 v_uv;
uniform vec2 tex_size;
out vec4 frag;
void main() { frag = vec4(v_uv * tex_size, 0.0, 1.0); }
)";

// The flat program draws the error pass's hit counts of every scene, so its positions go through
// the textured program's transform (w included): coverage is then that of the program the scene uses.
constexpr const char* kFlatVertex = R"(#version 330 core
layout(location = 0) in vec4 pos;
uniform vec2 scale;
void main() { gl_Position = vec4((pos.xy * scale - 1.0) * pos.w, (2.0 * pos.z - 1.0) * pos.w, pos.w); }
)";
constexpr const char* kFlatFragment = R"(#version 330 core
uniform vec4 color;
out vec4 frag;
void main() { frag = color; }
)";

Error gl_error(std::string what) {
  return make_error("llvmpipe peer: " + what + " (llvmpipe rows are omitted from the report)");
}

bool has_extension(const char* list, std::string_view name) {
  if (!list) return false;
  std::string_view all(list);
  std::size_t pos = 0;
  while ((pos = all.find(name, pos)) != std::string_view::npos) {
    const std::size_t end = pos + name.size();
    if ((pos == 0 || all[pos - 1] == ' ') && (end == all.size() || all[end] == ' ')) return true;
    pos = end;
  }
  return false;
}

Result<GLuint> compile(GLenum kind, const char* source) {
  GLuint s = glCreateShader(kind);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    glDeleteShader(s);
    return gl_error(std::string("shader compile failed: ") + log);
  }
  return s;
}

Result<GLuint> link(const char* vertex, const char* fragment) {
  auto vs = compile(GL_VERTEX_SHADER, vertex);
  if (!vs) return vs.error();
  auto fs = compile(GL_FRAGMENT_SHADER, fragment);
  if (!fs) {
    glDeleteShader(*vs);
    return fs.error();
  }
  GLuint p = glCreateProgram();
  glAttachShader(p, *vs);
  glAttachShader(p, *fs);
  glLinkProgram(p);
  glDeleteShader(*vs);
  glDeleteShader(*fs);
  GLint linked = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &linked);
  if (!linked) {
    glDeleteProgram(p);
    return gl_error("program link failed");
  }
  return p;
}

// One vertex array per layout, its attributes 0 (position) and 1 (colour or u/v) as the programs
// declare them.
void make_vertex_array(GLuint* vao, GLuint* vbo, Layout layout) {
  glGenVertexArrays(1, vao);
  glBindVertexArray(*vao);
  glGenBuffers(1, vbo);
  glBindBuffer(GL_ARRAY_BUFFER, *vbo);
  switch (layout) {
    case Layout::Gouraud:
      glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(GouraudVertex), reinterpret_cast<void*>(offsetof(GouraudVertex, x)));
      glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(GouraudVertex),
                            reinterpret_cast<void*>(offsetof(GouraudVertex, rgba)));
      glEnableVertexAttribArray(1);
      break;
    case Layout::Textured:
      glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, sizeof(TexturedVertex), reinterpret_cast<void*>(offsetof(TexturedVertex, x)));
      glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, sizeof(TexturedVertex), reinterpret_cast<void*>(offsetof(TexturedVertex, u)));
      glEnableVertexAttribArray(1);
      break;
    case Layout::Position:
      glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, sizeof(PositionVertex), reinterpret_cast<void*>(offsetof(PositionVertex, x)));
      break;
  }
  glEnableVertexAttribArray(0);
}

GLuint make_renderbuffer(GLenum format, unsigned w, unsigned h) {
  GLuint rb = 0;
  glGenRenderbuffers(1, &rb);
  glBindRenderbuffer(GL_RENDERBUFFER, rb);
  glRenderbufferStorage(GL_RENDERBUFFER, format, GLsizei(w), GLsizei(h));
  return rb;
}

}  // namespace

LlvmpipePeer::LlvmpipePeer(std::unique_ptr<Gl> gl) : gl_(std::move(gl)) {}
LlvmpipePeer::~LlvmpipePeer() = default;

Result<std::unique_ptr<LlvmpipePeer>> LlvmpipePeer::create(unsigned width, unsigned height) {
  if (width == 0 || height == 0 || width > 4096 || height > 4096) return gl_error("target size must be 1..4096");
  auto gl = std::make_unique<Gl>();
  gl->width = width;
  gl->height = height;
  const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  for (const char* ext : {"EGL_EXT_platform_base", "EGL_MESA_platform_surfaceless"})
    if (!has_extension(client_ext, ext)) return gl_error(std::string("EGL client extension ") + ext + " missing");
  auto get_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_display) return gl_error("eglGetPlatformDisplayEXT not available");
  gl->display = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (gl->display == EGL_NO_DISPLAY) return gl_error("no surfaceless EGL display");
  EGLint major = 0, minor = 0;
  if (!eglInitialize(gl->display, &major, &minor)) {
    gl->display = EGL_NO_DISPLAY;
    return gl_error("eglInitialize failed (is libegl-mesa0 installed?)");
  }
  const char* dpy_ext = eglQueryString(gl->display, EGL_EXTENSIONS);
  for (const char* ext : {"EGL_KHR_no_config_context", "EGL_KHR_surfaceless_context"})
    if (!has_extension(dpy_ext, ext)) return gl_error(std::string("EGL display extension ") + ext + " missing");
  if (!eglBindAPI(EGL_OPENGL_API)) return gl_error("eglBindAPI(OPENGL) failed");
  const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                            EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  gl->context = eglCreateContext(gl->display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
  if (gl->context == EGL_NO_CONTEXT) return gl_error("eglCreateContext (GL 3.3 core) failed");
  if (!eglMakeCurrent(gl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, gl->context)) return gl_error("eglMakeCurrent failed");
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  if (!renderer || std::strncmp(renderer, "llvmpipe", 8) != 0)
    return gl_error(std::string("renderer is \"") + (renderer ? renderer : "?") +
                    "\", not llvmpipe (set GALLIUM_DRIVER=llvmpipe LIBGL_ALWAYS_SOFTWARE=true)");

  gl->color_rb = make_renderbuffer(GL_RGBA8, width, height);
  gl->float_rb = make_renderbuffer(GL_RGBA32F, width, height);
  gl->depth_rb = make_renderbuffer(GL_DEPTH_COMPONENT24, width, height);
  for (auto [fbo, rb] : {std::pair{&gl->fbo_rgba8, gl->color_rb}, std::pair{&gl->fbo_float, gl->float_rb}}) {
    glGenFramebuffers(1, fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, *fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, gl->depth_rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) return gl_error("framebuffer incomplete");
  }
  glViewport(0, 0, GLsizei(width), GLsizei(height));

  // Every program is compiled and linked here, once; draws only switch between them.
  const std::pair<const char*, const char*> sources[kOutputs] = {
      {kGouraudVertex, kGouraudFragment}, {kTexturedVertex, kDecalFragment}, {kTexturedVertex, kTexelFragment},
      {kFlatVertex, kFlatFragment}};
  for (int i = 0; i < kOutputs; ++i) {
    auto p = link(sources[i].first, sources[i].second);
    if (!p) return p.error();
    gl->program[i] = *p;
    glUseProgram(*p);
    glUniform2f(glGetUniformLocation(*p, "scale"), 2.0f / float(width), 2.0f / float(height));
  }
  glUseProgram(gl->program[int(GlDrawState::Output::TextureDecal)]);
  glUniform1i(glGetUniformLocation(gl->program[int(GlDrawState::Output::TextureDecal)], "tex"), 0);
  gl->u_tex_size = glGetUniformLocation(gl->program[int(GlDrawState::Output::TexelCoordinates)], "tex_size");
  gl->u_flat_color = glGetUniformLocation(gl->program[int(GlDrawState::Output::FlatColor)], "color");
  for (int i = 0; i < kLayouts; ++i) make_vertex_array(&gl->vao[i], &gl->vbo[i], Layout(i));
  glGenTextures(1, &gl->texture);
  if (glGetError() != GL_NO_ERROR) return gl_error("OpenGL setup reported an error");

  std::unique_ptr<LlvmpipePeer> peer(new LlvmpipePeer(std::move(gl)));
  peer->renderer_ = renderer;
  return peer;
}

void LlvmpipePeer::set_texture(std::span<const std::uint8_t> rgba, unsigned width, unsigned height, bool bilinear) {
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, gl_->texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  // Texture row 0 is the top row (v = 0), the same as the device's texel (i, 0).
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, GLsizei(width), GLsizei(height), 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  const GLint filter = bilinear ? GL_LINEAR : GL_NEAREST;
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  gl_->tex_w = float(width);
  gl_->tex_h = float(height);
}

void LlvmpipePeer::set_vertices(std::span<const GlVertex> vertices, GlDrawState::Output output) {
  const Layout layout = layout_of(output);
  const int l = int(layout);
  glBindBuffer(GL_ARRAY_BUFFER, gl_->vbo[l]);
  auto upload = [&](const auto& packed) {
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(packed.size() * sizeof(packed[0])), packed.data(), GL_STATIC_DRAW);
  };
  switch (layout) {
    case Layout::Gouraud: {
      std::vector<GouraudVertex> packed(vertices.size());
      for (std::size_t i = 0; i < vertices.size(); ++i) {
        const GlVertex& v = vertices[i];
        packed[i] = {v.x, v.y, v.z, {unorm8(v.r), unorm8(v.g), unorm8(v.b), unorm8(v.a)}};
      }
      upload(packed);
      break;
    }
    case Layout::Textured: {
      std::vector<TexturedVertex> packed(vertices.size());
      for (std::size_t i = 0; i < vertices.size(); ++i) {
        const GlVertex& v = vertices[i];
        packed[i] = {v.x, v.y, v.z, v.w, v.u, v.v};
      }
      upload(packed);
      break;
    }
    case Layout::Position: {
      std::vector<PositionVertex> packed(vertices.size());
      for (std::size_t i = 0; i < vertices.size(); ++i) packed[i] = {vertices[i].x, vertices[i].y, vertices[i].z, vertices[i].w};
      upload(packed);
      break;
    }
  }
  gl_->vertex_count[l] = GLsizei(vertices.size());
}

void LlvmpipePeer::render(const GlDrawState& st) {
  const bool texel_out = st.output == GlDrawState::Output::TexelCoordinates;
  const int l = int(layout_of(st.output));
  glBindFramebuffer(GL_FRAMEBUFFER, texel_out ? gl_->fbo_float : gl_->fbo_rgba8);
  glUseProgram(gl_->program[int(st.output)]);
  glBindVertexArray(gl_->vao[l]);
  if (texel_out) glUniform2f(gl_->u_tex_size, gl_->tex_w, gl_->tex_h);
  if (st.output == GlDrawState::Output::FlatColor) glUniform4fv(gl_->u_flat_color, 1, st.flat_rgba);
  if (st.depth == GlDrawState::Depth::Off) {
    glDisable(GL_DEPTH_TEST);
  } else {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(st.depth == GlDrawState::Depth::Less        ? GL_LESS
                : st.depth == GlDrawState::Depth::LessEqual ? GL_LEQUAL
                                                            : GL_ALWAYS);
    glDepthMask(GL_TRUE);
  }
  if (st.blend == GlDrawState::Blend::Off || texel_out) {
    glDisable(GL_BLEND);
  } else {
    glEnable(GL_BLEND);
    if (st.blend == GlDrawState::Blend::Alpha) glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    else glBlendFunc(GL_ONE, GL_ONE);
  }
  if (st.clear) {
    glClearColor(0, 0, 0, texel_out ? 0.0f : 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }
  glDrawArrays(GL_TRIANGLES, 0, gl_->vertex_count[l]);
  glFinish();
}

std::vector<std::uint8_t> LlvmpipePeer::read_color() {
  glBindFramebuffer(GL_FRAMEBUFFER, gl_->fbo_rgba8);
  std::vector<std::uint8_t> out(std::size_t{gl_->width} * gl_->height * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, GLsizei(gl_->width), GLsizei(gl_->height), GL_RGBA, GL_UNSIGNED_BYTE, out.data());
  return out;
}

std::vector<std::uint32_t> LlvmpipePeer::read_depth24() {
  std::vector<std::uint32_t> out(std::size_t{gl_->width} * gl_->height);
  glReadPixels(0, 0, GLsizei(gl_->width), GLsizei(gl_->height), GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, out.data());
  for (auto& d : out) d >>= 8;  // GL_UNSIGNED_INT depth: the 24-bit value in the top bits
  return out;
}

std::vector<float> LlvmpipePeer::read_texel_coordinates() {
  glBindFramebuffer(GL_FRAMEBUFFER, gl_->fbo_float);
  std::vector<float> out(std::size_t{gl_->width} * gl_->height * 4);
  glReadPixels(0, 0, GLsizei(gl_->width), GLsizei(gl_->height), GL_RGBA, GL_FLOAT, out.data());
  return out;
}

Result<std::string> run_isolated(unsigned lp_threads, const std::function<Result<std::string>()>& work) {
  int fds[2];
  if (pipe(fds) != 0) return make_error(std::string("llvmpipe peer: pipe failed: ") + std::strerror(errno));
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    return make_error(std::string("llvmpipe peer: fork failed: ") + std::strerror(errno));
  }
  if (pid == 0) {
    close(fds[0]);
    setenv("LP_NUM_THREADS", std::to_string(lp_threads).c_str(), 1);
    auto r = work();
    // First byte: '1' = result, '0' = error message.
    const std::string msg = r ? "1" + *r : "0" + r.error().message;
    std::size_t done = 0;
    while (done < msg.size()) {
      const ssize_t n = write(fds[1], msg.data() + done, msg.size() - done);
      if (n <= 0) break;
      done += std::size_t(n);
    }
    close(fds[1]);
    _exit(0);
  }
  close(fds[1]);
  std::string text;
  char buf[65536];
  for (;;) {
    const ssize_t n = read(fds[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    text.append(buf, std::size_t(n));
  }
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (text.empty())
    return make_error("llvmpipe peer: the child process produced nothing (exit status " + std::to_string(status) +
                      "); llvmpipe rows omitted");
  if (text[0] != '1') return make_error(text.substr(1));
  return text.substr(1);
}

}  // namespace gpubridge::bench
