// Hub::hotplug_event (a libusb plug/unplug notification) against the hot-plug timer, in-process with
// a counting re-attach factory: an event runs the next step at once, and events arriving in bursts,
// or while a step is running, never start a second timer chain (at most one step in flight, and the
// polling rate stays one step per interval afterwards).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <random>
#include <thread>

#include "gpubridge/daemon/hub.hpp"
#include "gpubridge/daemon/test_backends.hpp"
#include "in_process_daemon.hpp"

namespace gpubridge::daemon {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

struct Counting {
  std::atomic<int> calls{0}, in_flight{0}, most_in_flight{0};
  std::chrono::milliseconds step{0};
  // Never finds a board (so every step is a new attempt); records overlap of steps.
  Hub::BackendFactory factory() {
    return [this]() -> Result<std::unique_ptr<backends::Backend>> {
      const int now = ++in_flight;
      int seen = most_in_flight.load();
      while (now > seen && !most_in_flight.compare_exchange_weak(seen, now)) {
      }
      std::this_thread::sleep_for(step);
      ++calls;
      --in_flight;
      return make_error("no board", backends::kDeviceGone);
    };
  }
};

fs::path temp_dir() {
  std::random_device rd;
  const fs::path dir = fs::temp_directory_path() / ("gbd-hpev-" + std::to_string(rd() % 1000000));
  fs::create_directories(dir);
  return dir;
}

// Waits until `pred` holds or `limit` passes.
template <class P>
bool eventually(P pred, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(2ms);
  }
  return true;
}

TEST(HotplugEvents, AnEventRunsTheNextStepAtOnce) {
  Counting c;
  Hub* hub = nullptr;
  const auto dir = temp_dir();
  {
    test::InProcessDaemon d;
    test::InProcessDaemon::Options o;
    o.before_listening = [&](Hub& h) {
      h.enable_hotplug(c.factory(), 600000ms);  // the poll never comes during the test
      hub = &h;
    };
    std::string why;
    ASSERT_TRUE(d.start(std::make_unique<FakeScanoutBackend>(), dir, why, o)) << why;
    std::this_thread::sleep_for(50ms);
    EXPECT_EQ(c.calls.load(), 0);
    hub->hotplug_event();
    EXPECT_TRUE(eventually([&] { return c.calls.load() == 1; }, 2000ms)) << c.calls.load();
    hub->hotplug_event();
    EXPECT_TRUE(eventually([&] { return c.calls.load() == 2; }, 2000ms)) << c.calls.load();
    std::this_thread::sleep_for(100ms);
    EXPECT_EQ(c.calls.load(), 2) << "a step ran without an event or a poll";
  }
  fs::remove_all(dir);
}

TEST(HotplugEvents, BurstsAndEventsDuringAStepKeepOneTimerChain) {
  Counting c;
  c.step = 20ms;  // long enough that most events of the burst land while a step runs
  Hub* hub = nullptr;
  const auto dir = temp_dir();
  {
    test::InProcessDaemon d;
    test::InProcessDaemon::Options o;
    o.before_listening = [&](Hub& h) {
      h.enable_hotplug(c.factory(), 100ms);
      hub = &h;
    };
    std::string why;
    ASSERT_TRUE(d.start(std::make_unique<FakeScanoutBackend>(), dir, why, o)) << why;
    for (int i = 0; i < 200; ++i) {
      hub->hotplug_event();
      if (i % 10 == 0) std::this_thread::sleep_for(3ms);
    }
    std::this_thread::sleep_for(200ms);  // the burst's pokes are used up
    const int before = c.calls.load();
    std::this_thread::sleep_for(1000ms);
    const int during = c.calls.load() - before;
    EXPECT_EQ(c.most_in_flight.load(), 1) << "two steps ran at once";
    // One chain: at most one step per (100 ms interval + 20 ms step) → about 8 in a second. A
    // second chain would double that. A slow machine only makes it fewer.
    EXPECT_LE(during, 10) << "more steps than one timer chain makes: " << during;
    EXPECT_GE(during, 1) << "polling stopped after the burst";
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gpubridge::daemon
