// The examples end to end against a real gpubridged process on the simulator: a few frames of
// each stream over the Unix socket through ClientSink, and the frame read back from the daemon's
// device equals the committed golden PNG (the same exact simulator, reached over the socket).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <random>
#include <thread>

#include "gpubridge/draw/client_sink.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/examples/golden.hpp"

namespace gpubridge::examples {
namespace {

namespace fs = std::filesystem;

// A gpubridged child process serving the simulator on a private Unix socket.
class DaemonProcess {
 public:
  DaemonProcess() {
    std::random_device rd;
    dir_ = fs::temp_directory_path() / ("gbex-" + std::to_string(rd() % 1000000));
    fs::create_directories(dir_);
    socket_ = (dir_ / "d.sock").string();
    pid_ = ::fork();
    if (pid_ == 0) {
      const std::string listen = "unix:" + socket_;
      ::execl(GPUBRIDGED_PATH, GPUBRIDGED_PATH, "--listen", listen.c_str(), "--backend", "sim", "--log-level", "error",
              static_cast<char*>(nullptr));
      ::_exit(127);
    }
    for (int i = 0; i < 200 && !fs::exists(socket_); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  ~DaemonProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  bool running() const { return pid_ > 0 && fs::exists(socket_); }
  std::string address() const { return "unix:" + socket_; }

 private:
  fs::path dir_;
  std::string socket_;
  pid_t pid_ = -1;
};

TEST(ExamplesOnDaemon, FewFramesEachMatchTheGoldens) {
  DaemonProcess daemon;
  ASSERT_TRUE(daemon.running()) << "gpubridged did not create its socket";
  auto sink = draw::ClientSink::connect(daemon.address(), "examples-test");
  ASSERT_TRUE(sink) << sink.error().message;
  for (auto& ex : make_examples()) {
    const std::string name = ex->info().name;
    auto ctx = draw::Context::create(**sink, ex->options());
    ASSERT_TRUE(ctx) << name << ": " << ctx.error().message;
    // Three frames ending with the golden one (frame n depends only on n).
    auto r = run_frames(*ex, *ctx, kGoldenFrame - 2, 3);
    ASSERT_TRUE(r) << r.error().message;
    auto shown = ctx->read_display();
    ASSERT_TRUE(shown) << name << ": " << shown.error().message;
    auto golden = load_png(golden_path(GPUBRIDGE_GOLDEN_DIR, name));
    ASSERT_TRUE(golden) << golden.error().message;
    const auto diff = compare_images(*golden, *shown);
    EXPECT_TRUE(diff.identical()) << name << " over the daemon: " << diff.summary();
  }
}

}  // namespace
}  // namespace gpubridge::examples
