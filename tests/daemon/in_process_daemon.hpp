#pragma once
// gpubridged's wiring (daemon/src/main.cpp) inside the test process: a network thread and a device
// thread, a Hub over the given backend and a Server listening on `dir`/d.sock. For tests that need
// to reach into the daemon while it serves real socket clients (the mirror suite changes the
// board's memory behind the host's back; the auto-attach suite plugs a board in after start).
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <boost/asio.hpp>

#include "gpubridge/client/address.hpp"
#include "gpubridge/daemon/hub.hpp"
#include "gpubridge/daemon/server.hpp"

namespace gpubridge::test {

class InProcessDaemon {
 public:
  struct Options {
    daemon::HubOptions hub;
    daemon::Hub::BackendFactory fallback;               // as gpubridged's make_simulator; empty: none
    std::function<void(daemon::Hub&)> before_listening;  // e.g. enable_hotplug
  };

  InProcessDaemon() = default;
  InProcessDaemon(const InProcessDaemon&) = delete;
  InProcessDaemon& operator=(const InProcessDaemon&) = delete;

  // Starts serving `backend`; false with the reason in `why` when it cannot listen.
  bool start(std::unique_ptr<backends::Backend> backend, const std::filesystem::path& dir, std::string& why,
             Options options = {}) {
    hub_.emplace(net_.get_executor(), device_.get_executor(), std::move(backend), options.hub, options.fallback);
    if (options.before_listening) options.before_listening(*hub_);
    server_.emplace(net_, *hub_);
    auto a = client::parse_address("unix:" + (dir / "d.sock").string());
    if (!a) return (why = a.error().message, false);
    auto bound = server_->listen(*a);
    if (!bound) return (why = bound.error().message, false);
    address_ = bound->to_string();
    device_thread_ = std::thread([this] { device_.run(); });
    net_thread_ = std::thread([this] { net_.run(); });
    return true;
  }

  // Stops like gpubridged on SIGTERM: listeners closed, no more re-attach attempts or device work,
  // sessions told; the socket and lock files go last.
  ~InProcessDaemon() {
    if (server_)
      boost::asio::post(net_, [this] {
        server_->stop_accepting();
        hub_->stop();
        hub_->shutdown_sessions();
      });
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    net_.stop();
    if (net_thread_.joinable()) net_thread_.join();
    device_guard_.reset();
    device_.stop();
    if (device_thread_.joinable()) device_thread_.join();
    server_.reset();
    hub_.reset();
  }

  const std::string& address() const { return address_; }
  // Work posted here runs on the device thread, between backend calls.
  boost::asio::io_context& device_context() { return device_; }

 private:
  boost::asio::io_context net_{1}, device_{1};
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> device_guard_ =
      boost::asio::make_work_guard(device_);
  std::optional<daemon::Hub> hub_;
  std::optional<daemon::Server> server_;
  std::string address_;
  std::thread net_thread_, device_thread_;
};

}  // namespace gpubridge::test
