// Runs bench/llvmpipe/minimal_gl.c beside the peer (see minimal_gl_runner.hpp).
#include "minimal_gl_runner.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

#include "error_measure.hpp"
#include "gpubridge/bench/llvmpipe_peer.hpp"

namespace gpubridge::bench {
namespace {

namespace fs = std::filesystem;

// The file minimal_gl.c reads: per vertex float x, y, z then R, G, B, A bytes (16 bytes, host order).
std::vector<std::uint8_t> vertex_file(const Scene& s) {
  std::vector<std::uint8_t> out(s.triangles.size() * 3 * 16);
  GlVertex v[3];
  std::uint8_t* p = out.data();
  for (const auto& t : s.triangles) {
    to_gl(t, v);
    for (const GlVertex& g : v) {
      const float xyz[3] = {g.x, g.y, g.z};
      std::memcpy(p, xyz, 12);
      p[12] = unorm8(g.r), p[13] = unorm8(g.g), p[14] = unorm8(g.b), p[15] = unorm8(g.a);
      p += 16;
    }
  }
  return out;
}

Error minimal_error(const std::string& what) { return make_error("minimal GL program: " + what); }

}  // namespace

bool minimal_gl_draws(const Scene& s) {
  return !s.textured && s.state.z_test && s.state.z_write && s.state.z_func == protocol::DepthFunc::Less &&
         s.state.blend == protocol::BlendMode::Off;
}

Result<std::string> find_minimal_gl() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  for (const fs::path& p : {self.parent_path() / "minimal_gl", self.parent_path() / ".." / "bench" / "llvmpipe" / "minimal_gl"})
    if (fs::exists(p, ec)) return p.string();
  return minimal_error("minimal_gl not found next to " + self.string() +
                       " (it is built with the llvmpipe peer: libegl-dev libopengl-dev)");
}

Result<MinimalGlRun> run_minimal_gl(const std::string& exe, const Scene& s, unsigned lp_threads,
                                    const FrameBudget& budget) {
  std::string path = (fs::temp_directory_path() / "gpubridge-minimal-gl-XXXXXX").string();
  const int fd = mkstemp(path.data());
  if (fd < 0) return minimal_error(std::string("cannot create a temporary vertex file: ") + std::strerror(errno));
  const auto bytes = vertex_file(s);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = write(fd, bytes.data() + done, bytes.size() - done);
    if (n <= 0) break;
    done += std::size_t(n);
  }
  close(fd);
  struct Unlink {
    std::string p;
    ~Unlink() { unlink(p.c_str()); }
  } remove_file{path};
  if (done != bytes.size()) return minimal_error("cannot write the temporary vertex file " + path);

  int out[2];
  if (pipe(out) != 0) return minimal_error(std::string("pipe failed: ") + std::strerror(errno));
  const std::string w = std::to_string(s.width), h = std::to_string(s.height), r = std::to_string(budget.runs);
  const std::string min_ms = std::to_string(static_cast<unsigned>(budget.min_seconds * 1e3 + 0.5));
  const pid_t pid = fork();
  if (pid < 0) {
    close(out[0]);
    close(out[1]);
    return minimal_error(std::string("fork failed: ") + std::strerror(errno));
  }
  if (pid == 0) {
    dup2(out[1], STDOUT_FILENO);
    close(out[0]);
    close(out[1]);
    setenv("LP_NUM_THREADS", std::to_string(lp_threads).c_str(), 1);
    const char* argv[] = {exe.c_str(), path.c_str(), w.c_str(), h.c_str(), r.c_str(), min_ms.c_str(), nullptr};
    execv(exe.c_str(), const_cast<char* const*>(argv));
    _exit(127);
  }
  close(out[1]);
  std::string text;
  char buf[4096];
  for (;;) {
    const ssize_t n = read(out[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    text.append(buf, std::size_t(n));
  }
  close(out[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    return minimal_error(exe + " failed on scene " + s.name + " (exit status " + std::to_string(status) +
                         "; its message is on stderr)");
  unsigned long long triangles = 0;
  MinimalGlRun run;
  if (std::sscanf(text.c_str(), "triangles=%llu best_seconds=%lf pixel_sum=%llu frames=%u", &triangles,
                  &run.best_seconds, &run.pixel_sum, &run.frames) != 4 ||
      triangles != s.triangles.size() || !(run.best_seconds > 0) || run.frames < budget.runs)
    return minimal_error("unexpected output from " + exe + " on scene " + s.name + ": " + text);
  return run;
}

}  // namespace gpubridge::bench
