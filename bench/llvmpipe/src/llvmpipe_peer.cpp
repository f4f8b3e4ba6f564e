// EGL surfaceless + FBO rendering with Mesa llvmpipe (see llvmpipe_peer.hpp).
#define GL_GLEXT_PROTOTYPES 1
#include "gpubridge/bench/llvmpipe_peer.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string_view>

namespace gpubridge::bench {

struct LlvmpipePeer::Gl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  unsigned width = 0, height = 0;
  GLuint fbo_rgba8 = 0, fbo_float = 0, color_rb = 0, float_rb = 0, depth_rb = 0;
  GLuint program = 0, vao = 0, vbo = 0, texture = 0;
  GLint u_scale = -1, u_mode = -1, u_tex_size = -1;
  GLsizei vertex_count = 0;
  float tex_w = 1, tex_h = 1;

  ~Gl() {
    if (display == EGL_NO_DISPLAY) return;
    if (context != EGL_NO_CONTEXT) {
      glDeleteBuffers(1, &vbo);
      glDeleteVertexArrays(1, &vao);
      glDeleteTextures(1, &texture);
      glDeleteProgram(program);
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

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec4 pos;    // x, y in pixels (y down), z in [0, 1], w
layout(location = 1) in vec4 color;
layout(location = 2) in vec2 uv;
uniform vec2 scale;                  // 2 / width, 2 / height
noperspective out vec4 v_color;      // the device's Gouraud is linear in screen space
out vec2 v_uv;                       // perspective-correct
void main() {
  vec2 ndc = pos.xy * scale - 1.0;   // no y flip: FBO row r is window y in [r, r + 1)
  gl_Position = vec4(ndc * pos.w, (2.0 * pos.z - 1.0) * pos.w, pos.w);
  v_color = color;
  v_uv = uv;
}
)";

constexpr const char* kFragmentShader = R"(#version 330 core
noperspective in vec4 v_color;
in vec2 v_uv;
uniform int mode;                    // 0 colour, 1 texture decal, 2 texel coordinates
uniform sampler2D tex;
uniform vec2 tex_size;
out vec4 frag;
void main() {
  if (mode == 0) frag = v_color;
  else if (mode == 1) frag = texture(tex, v_uv);
  else frag = vec4(v_uv * tex_size, 0.0, 1.0);
}
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

  auto vs = compile(GL_VERTEX_SHADER, kVertexShader);
  if (!vs) return vs.error();
  auto fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  if (!fs) return fs.error();
  gl->program = glCreateProgram();
  glAttachShader(gl->program, *vs);
  glAttachShader(gl->program, *fs);
  glLinkProgram(gl->program);
  glDeleteShader(*vs);
  glDeleteShader(*fs);
  GLint linked = 0;
  glGetProgramiv(gl->program, GL_LINK_STATUS, &linked);
  if (!linked) return gl_error("program link failed");
  glUseProgram(gl->program);
  gl->u_scale = glGetUniformLocation(gl->program, "scale");
  gl->u_mode = glGetUniformLocation(gl->program, "mode");
  gl->u_tex_size = glGetUniformLocation(gl->program, "tex_size");
  glUniform2f(gl->u_scale, 2.0f / float(width), 2.0f / float(height));
  glUniform1i(glGetUniformLocation(gl->program, "tex"), 0);

  glGenVertexArrays(1, &gl->vao);
  glBindVertexArray(gl->vao);
  glGenBuffers(1, &gl->vbo);
  glBindBuffer(GL_ARRAY_BUFFER, gl->vbo);
  const GLsizei stride = sizeof(GlVertex);
  glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(GlVertex, x)));
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(GlVertex, r)));
  glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offsetof(GlVertex, u)));
  for (GLuint i = 0; i < 3; ++i) glEnableVertexAttribArray(i);
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

void LlvmpipePeer::set_vertices(std::span<const GlVertex> vertices) {
  glBindBuffer(GL_ARRAY_BUFFER, gl_->vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size_bytes()), vertices.data(), GL_STATIC_DRAW);
  gl_->vertex_count = GLsizei(vertices.size());
}

void LlvmpipePeer::render(const GlDrawState& st) {
  const bool texel_out = st.output == GlDrawState::Output::TexelCoordinates;
  glBindFramebuffer(GL_FRAMEBUFFER, texel_out ? gl_->fbo_float : gl_->fbo_rgba8);
  glUniform1i(gl_->u_mode, texel_out ? 2 : st.output == GlDrawState::Output::TextureDecal ? 1 : 0);
  glUniform2f(gl_->u_tex_size, gl_->tex_w, gl_->tex_h);
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
  glDrawArrays(GL_TRIANGLES, 0, gl_->vertex_count);
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
