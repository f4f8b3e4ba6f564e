/* The plainest Gouraud program a GL programmer would write, as a yardstick for the llvmpipe peer of
 * `gpubridge bench accuracy` (issue 17). No project code: EGL surfaceless, GL 3.3 core, one program
 * (a noperspective colour varying, frag = colour), one static vertex buffer, depth LESS, a 640x480-style
 * RGBA8 + DEPTH24 framebuffer object; each frame is glClear + one glDrawArrays + glFinish.
 *
 * Usage: minimal_gl VERTICES WIDTH HEIGHT RUNS [MIN_MS]
 *   VERTICES: 16-byte little-endian records, 3 per triangle: float x, y (pixels, y down), z (0..1),
 *   then R, G, B, A bytes. LP_NUM_THREADS in the environment picks llvmpipe's thread count.
 * Prints "triangles=N best_seconds=S pixel_sum=P frames=F": the best of at least RUNS frames after one warm-up
 * frame, and of more until MIN_MS milliseconds of timed frames have passed (at most 2000 frames; the
 * rule of the bench's bench/src/best_frame.hpp); P is the sum of every RGBA byte of the last frame,
 * so a caller can check what was drawn; F counts the timed frames. */
#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char* vs_src =
    "#version 330 core\n"
    "layout(location = 0) in vec3 pos;\n"
    "layout(location = 1) in vec4 color;\n"
    "uniform vec2 scale;\n"
    "noperspective out vec4 v_color;\n"
    "void main() { gl_Position = vec4(pos.xy * scale - 1.0, 2.0 * pos.z - 1.0, 1.0); v_color = color; }\n";
static const char* fs_src =
    "#version 330 core\n"
    "noperspective in vec4 v_color;\n"
    "out vec4 frag;\n"
    "void main() { frag = v_color; }\n";

static int fail(const char* what) {
  fprintf(stderr, "minimal_gl: %s\n", what);
  return 1;
}

static GLuint shader(GLenum kind, const char* src) {
  GLuint s = glCreateShader(kind);
  GLint ok = 0;
  glShaderSource(s, 1, &src, NULL);
  glCompileShader(s);
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  return ok ? s : 0;
}

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

int main(int argc, char** argv) {
  if (argc != 5 && argc != 6) return fail("usage: minimal_gl VERTICES WIDTH HEIGHT RUNS [MIN_MS]");
  /* llvmpipe allocates and frees its binned scene every frame. With glibc's start-up thresholds the
   * heap top is trimmed after each frame and faulted in again by the next (a fifth of a frame of
   * 10-px triangles); a program that has freed a large block runs with the thresholds raised. Fix
   * them at that raised state, as the peer does (llvmpipe_runner.cpp), so neither depends on its
   * allocation history. */
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
  const int w = atoi(argv[2]), h = atoi(argv[3]), runs = atoi(argv[4]), min_ms = argc == 6 ? atoi(argv[5]) : 0;
  if (w < 1 || h < 1 || w > 4096 || h > 4096 || runs < 1 || min_ms < 0 || min_ms > 60000)
    return fail("WIDTH, HEIGHT must be 1..4096, RUNS >= 1, MIN_MS 0..60000");
  FILE* f = fopen(argv[1], "rb");
  if (!f) return fail("cannot open the vertex file");
  fseek(f, 0, SEEK_END);
  const long bytes = ftell(f);
  fseek(f, 0, SEEK_SET);
  if (bytes <= 0 || bytes % 48 != 0) return fail("the vertex file is not a whole number of 48-byte triangles");
  unsigned char* data = malloc((size_t)bytes);
  if (!data || fread(data, 1, (size_t)bytes, f) != (size_t)bytes) return fail("cannot read the vertex file");
  fclose(f);

  PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
      (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
  EGLDisplay dpy = get_display ? get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL) : EGL_NO_DISPLAY;
  if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, NULL, NULL)) return fail("no surfaceless EGL display");
  const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext ctx = eglBindAPI(EGL_OPENGL_API) ? eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs)
                                              : EGL_NO_CONTEXT;
  if (ctx == EGL_NO_CONTEXT || !eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx))
    return fail("no GL 3.3 core context");
  const char* renderer = (const char*)glGetString(GL_RENDERER);
  if (!renderer || strncmp(renderer, "llvmpipe", 8) != 0) return fail("the renderer is not llvmpipe");

  GLuint rb[2], fbo, prog = glCreateProgram(), vao, vbo;
  glGenRenderbuffers(2, rb);
  glBindRenderbuffer(GL_RENDERBUFFER, rb[0]);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
  glBindRenderbuffer(GL_RENDERBUFFER, rb[1]);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb[1]);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) return fail("framebuffer incomplete");
  glViewport(0, 0, w, h);

  GLuint vs = shader(GL_VERTEX_SHADER, vs_src), fs = shader(GL_FRAGMENT_SHADER, fs_src);
  GLint linked = 0;
  if (!vs || !fs) return fail("shader compile failed");
  glAttachShader(prog, vs);
  glAttachShader(prog, fs);
  glLinkProgram(prog);
  glGetProgramiv(prog, GL_LINK_STATUS, &linked);
  if (!linked) return fail("program link failed");
  glUseProgram(prog);
  glUniform2f(glGetUniformLocation(prog, "scale"), 2.0f / (float)w, 2.0f / (float)h);

  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(1, &vbo);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glBufferData(GL_ARRAY_BUFFER, bytes, data, GL_STATIC_DRAW);
  free(data); /* GL has its copy */
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 16, (void*)0);
  glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, 16, (void*)12);
  glEnableVertexAttribArray(0);
  glEnableVertexAttribArray(1);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glClearColor(0, 0, 0, 1);
  if (glGetError() != GL_NO_ERROR) return fail("OpenGL setup reported an error");

  double best = 1e30, spent = 0;
  int r = 0; /* frame 0 warms up (JIT, buffer placement) */
  for (; r <= runs || (spent < min_ms * 1e-3 && r <= 2000); ++r) {
    const double t0 = now();
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDrawArrays(GL_TRIANGLES, 0, (GLsizei)(bytes / 16));
    glFinish();
    const double t = now() - t0;
    if (r > 0 && t < best) best = t;
    if (r > 0) spent += t;
  }
  unsigned char* pixels = malloc((size_t)w * (size_t)h * 4);
  unsigned long long sum = 0;
  if (!pixels) return fail("out of memory");
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, pixels);
  for (size_t i = 0; i < (size_t)w * (size_t)h * 4; ++i) sum += pixels[i];
  printf("triangles=%ld best_seconds=%.9f pixel_sum=%llu frames=%d\n", bytes / 48, best, sum, r - 1);
  free(pixels);
  eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(dpy, ctx);
  eglTerminate(dpy);
  return 0;
}
