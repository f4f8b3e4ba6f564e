// `gpubridged --backend auto` started with no board picks up a board plugged in later (issue 4,
// docs/daemon.md "Hot-plug"): the daemon's Hub and Server in-process on the simulator, with the
// real auto re-attach factory (board profiles → libusb enumeration/open → FTDI MPSSE driver →
// attach) running against a umockdev testbed that is empty at first and then gets an FT232H
// whose usbfs ioctls are answered by the byte-exact MPSSE model.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <random>
#include <thread>

#include <nlohmann/json.hpp>

#include "gpubridge/client/client.hpp"
#include "gpubridge/daemon/backend_factory.hpp"
#include "gpubridge/daemon/config.hpp"
#include "gpubridge/daemon/hub.hpp"
#include "gpubridge/daemon/server.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "client_checks.hpp"
#include "in_process_daemon.hpp"
#include "umockdev_bed.hpp"

namespace gpubridge {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace std::chrono_literals;
using test::status_of;
using test::wait_event;

fs::path make_temp_dir() {
  std::random_device rd;
  fs::path dir = fs::temp_directory_path() / ("gb-autoattach-" + std::to_string(rd() % 1000000));
  fs::create_directories(dir / "boards");
  return dir;
}



// gpubridged's wiring (main.cpp) for `--backend auto`, in-process: network and device threads,
// the simulator fallback and the auto re-attach factory.
class InProcessAutoDaemon {
 public:
  // Starts like gpubridged: make_backend("auto") first (with the testbed as it is now), then the
  // hot-plug timer and, with `notifications`, the libusb hot-plug watch.
  bool start(const daemon::DaemonConfig& cfg, const fs::path& socket_dir, std::string& started_on, std::string& why,
             bool notifications = false) {
    auto backend = daemon::make_backend(cfg.backend, cfg);
    if (!backend) return (why = backend.error().message, false);
    started_on = (*backend)->info().backend;
    test::InProcessDaemon::Options opts;
    opts.fallback = [cfg] { return daemon::make_simulator(cfg); };
    opts.before_listening = [this, &cfg, notifications, &why](daemon::Hub& hub) {
      hub.enable_hotplug(daemon::make_reattach_factory(cfg), std::chrono::milliseconds(cfg.reattach_interval_ms));
      if (!notifications) return;
      auto watch = daemon::watch_board_usb(cfg, [&hub] { hub.hotplug_event(); });
      if (!watch) why = watch.error().message;
      else watch_ = std::move(*watch);
      hub.set_hotplug_notifications(watch_ != nullptr);
    };
    return daemon_.start(std::move(*backend), socket_dir, why, opts) && (!notifications || watch_);
  }
  const std::string& address() const { return daemon_.address(); }

 private:
  test::InProcessDaemon daemon_;
  std::shared_ptr<void> watch_;  // after daemon_: stops watching before the hub goes
};

// `--backend auto` over a boards directory holding only the profile that matches the testbed's
// FT232H, so every attempt is this board's open.
daemon::DaemonConfig auto_config(const fs::path& dir, unsigned reattach_interval_ms) {
  fs::copy_file(fs::path(GPUBRIDGE_TEST_CONFIG_DIR) / "boards" / "ft232h-generic.json", dir / "boards" / "ft232h-generic.json");
  daemon::DaemonConfig cfg;
  cfg.backend = "auto";
  cfg.boards_dir = dir.string();
  cfg.reattach_interval_ms = reattach_interval_ms;
  return cfg;
}

TEST(AutoAttach, BoardPluggedInAfterStartReplacesTheSimulator) {
  usb::testing::Bed bed(/*plugged=*/false);
  const fs::path dir = make_temp_dir();
  const auto cfg = auto_config(dir, 50);

  std::string started_on, why;
  {
    InProcessAutoDaemon d;
    ASSERT_TRUE(d.start(cfg, dir, started_on, why)) << why;
    ASSERT_EQ(started_on, "sim") << "auto found a board in an empty testbed";

    auto c = client::Client::connect(d.address(), 2000ms);
    ASSERT_TRUE(c) << c.error().message;
    ASSERT_TRUE(c->handshake("watcher", "", 2000ms));

    // No board: it keeps serving the simulator, and status claims no attach or detach.
    std::this_thread::sleep_for(300ms);  // several 50 ms attempts, all finding nothing
    {
      const auto st = status_of(*c);
      EXPECT_EQ(st["backend"], "sim") << st.dump();
      EXPECT_EQ(st["hotplug"]["enabled"], true) << st.dump();
      EXPECT_EQ(st["hotplug"]["attached"], false) << st.dump();
      EXPECT_EQ(st["hotplug"]["awaiting_first_board"], true) << st.dump();
      EXPECT_EQ(st["hotplug"]["detaches"], 0) << st.dump();
      EXPECT_EQ(st["hotplug"]["reattaches"], 0) << st.dump();
    }
    EXPECT_TRUE(c->take_device_events().empty()) << "an event without any board";
    EXPECT_EQ(bed.bulk_urbs.load(), 0u) << "no device, yet bulk transfers happened";

    bed.plug();
    const auto back = wait_event(*c, "device_back", 5000ms);
    ASSERT_TRUE(back) << "no device_back event after the board was plugged in";
    EXPECT_EQ((*back)["backend"], "board") << back->dump();
    EXPECT_EQ((*back)["board"], "ft232h-generic") << back->dump();
    EXPECT_EQ((*back)["state"], "reset") << back->dump();
    EXPECT_EQ((*back)["first_attach"], true) << back->dump();
    {
      const auto st = status_of(*c);
      EXPECT_EQ(st["backend"], "board") << st.dump();
      EXPECT_EQ(st["board"], "ft232h-generic") << st.dump();
      EXPECT_EQ(st["hotplug"]["attached"], true) << st.dump();
      EXPECT_EQ(st["hotplug"]["awaiting_first_board"], false) << st.dump();
      EXPECT_EQ(st["hotplug"]["detaches"], 0) << st.dump();
      EXPECT_EQ(st["hotplug"]["reattaches"], 0) << "a first attach is not a re-attach: " << st.dump();
    }

    // Commands now go through libusb to the model: an ID read costs bulk URBs and returns the
    // reference target's ID.
    ASSERT_TRUE(c->acquire_lease(protocol::LeaseMode::Wait, 2000ms));
    const unsigned urbs_before = bed.bulk_urbs.load();
    auto id = c->read_register(protocol::index_of(protocol::Reg::ID), 2000ms);
    ASSERT_TRUE(id) << id.error().message;
    EXPECT_EQ(*id >> 56, 0x53u);
    EXPECT_GT(bed.bulk_urbs.load(), urbs_before) << "the ID read did not reach the USB device";
    EXPECT_TRUE(bed.model.violations().empty()) << bed.model.violations()[0];
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// With libusb hot-plug notifications the plug and the unplug take effect at once: the poll
// interval here is ten minutes, so without the notification neither would happen in the test.
TEST(AutoAttach, UsbNotificationsAttachAndDetachWithoutWaitingForThePoll) {
  usb::testing::Bed bed(/*plugged=*/false);
  const fs::path dir = make_temp_dir();
  const auto cfg = auto_config(dir, 600000);

  std::string started_on, why;
  {
    InProcessAutoDaemon d;
    ASSERT_TRUE(d.start(cfg, dir, started_on, why, /*notifications=*/true)) << why;
    ASSERT_EQ(started_on, "sim");
    auto c = client::Client::connect(d.address(), 2000ms);
    ASSERT_TRUE(c) << c.error().message;
    ASSERT_TRUE(c->handshake("watcher", "", 2000ms));
    {
      const auto st = status_of(*c);
      EXPECT_EQ(st["hotplug"]["usb_notifications"], true) << st.dump();
      EXPECT_EQ(st["hotplug"]["usb_events"], 0) << st.dump();
    }

    const auto t0 = std::chrono::steady_clock::now();
    bed.plug();
    umockdev_testbed_uevent(bed.testbed, "/sys/devices/usb1", "add");  // what the kernel announces
    const auto back = wait_event(*c, "device_back", 5000ms);
    ASSERT_TRUE(back) << "the plug notification did not start an attach";
    EXPECT_EQ((*back)["board"], "ft232h-generic") << back->dump();
    EXPECT_EQ((*back)["first_attach"], true) << back->dump();
    const auto attach_ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0);
    std::printf("attached %lld ms after the plug notification\n", static_cast<long long>(attach_ms.count()));
    {
      const auto st = status_of(*c);
      EXPECT_EQ(st["backend"], "board") << st.dump();
      EXPECT_GE(st["hotplug"]["usb_events"].get<int>(), 1) << st.dump();
    }

    // Unplug: URBs fail with ENODEV from now on, and the kernel announces the removal. Nobody is
    // sending commands, so only the notification's presence probe can notice it.
    bed.model.faults().at_op = bed.model.faults().ops;
    bed.model.faults().fault = usb::emu::UsbFault::NoDevice;
    umockdev_testbed_uevent(bed.testbed, "/sys/devices/usb1", "remove");
    const auto gone = wait_event(*c, "device_gone", 5000ms);
    ASSERT_TRUE(gone) << "the unplug notification did not start a presence probe";
    const auto st = status_of(*c);
    EXPECT_EQ(st["backend"], "sim") << st.dump();
    EXPECT_EQ(st["hotplug"]["detaches"], 1) << st.dump();
    EXPECT_GE(st["hotplug"]["usb_events"].get<int>(), 2) << st.dump();
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace gpubridge
