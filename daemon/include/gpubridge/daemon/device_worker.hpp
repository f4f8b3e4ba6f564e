#pragma once
// DeviceWorker: the backend and the thread it runs on. Every device operation is a request:
// `work(backend)` runs on the device executor, one request at a time in the order they were made,
// and `done(result)` runs on the network executor, so a slow device never blocks network I/O.
//
// Requests can be cancelled, per session (its client went away) or all at once (stop(), on
// SIGTERM): a request that has not started is answered kCancelled without touching the device, and
// the running one stops at its next cancel point, between frames of a write batch (the backend
// polls abort_ through Backend::set_cancel_flag) or between the slices of an upload.
#include <atomic>
#include <functional>
#include <memory>
#include <mutex>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/daemon/mirror_backend.hpp"

namespace gpubridge::daemon {

using BackendFactory = std::function<Result<std::unique_ptr<backends::Backend>>()>;

class DeviceWorker {
 public:
  using Executor = boost::asio::any_io_executor;
  using CancelFlag = std::atomic<bool>;

  DeviceWorker(Executor net, Executor device, std::unique_ptr<backends::Backend> backend);
  ~DeviceWorker();
  DeviceWorker(const DeviceWorker&) = delete;
  DeviceWorker& operator=(const DeviceWorker&) = delete;

  // Runs work(Backend&) -> Result<T> on the device thread and done(Result<T>) on the network
  // thread. `cancel` (may be null) is the requester's flag: once it is set, see cancel().
  template <class T, class Work, class Done>
  void request(std::shared_ptr<CancelFlag> cancel, Work work, Done done);
  // Sets `cancel` and stops the request running under it at its next cancel point (any thread).
  void cancel(const std::shared_ptr<CancelFlag>& cancel);
  // Shutdown: nothing starts any more, the running request stops at its next cancel point, and the
  // scanout callback is no longer called (any thread).
  void stop();
  bool stopping() const { return stopping_.load(); }

  // --- device thread (request bodies, hot-plug steps) ---
  backends::Backend& backend() { return *backend_; }
  bool aborted() const { return abort_.load(std::memory_order_relaxed); }  // a cancel point says stop
  // Replaces the backend between two requests (hot-plug); the scanout callback moves over.
  void install(std::unique_ptr<backends::Backend> backend);
  // Called on the device thread when a request found the device gone (kDeviceGone).
  void on_device_gone(std::function<void(const Error&)> f) { on_gone_ = std::move(f); }
  // Every scanned-out frame (device thread); set before the loops run.
  void set_scanout_callback(backends::ScanoutCallback cb);

  // --- any thread ---
  // The mirror decorator's counters summed over every MirrorBackend served (zero without mirror mode).
  MirrorCounters mirror_counters() const;

  static Error cancelled_error() { return make_error("cancelled", backends::kCancelled); }

 private:
  bool begin(const std::shared_ptr<CancelFlag>& cancel);  // false: do not start, answer kCancelled
  void end();
  void report(const Error& e) {
    if (e.code == backends::kDeviceGone && on_gone_) on_gone_(e);
  }

  Executor net_, device_;
  std::unique_ptr<backends::Backend> backend_;
  // STATUS (network thread) reads the mirror's counters while the device thread works: this mutex
  // keeps backend_ in place meanwhile; install() swaps under it.
  mutable std::mutex backend_mu_;
  MirrorCounters retired_mirror_counters_;  // of mirrors replaced by hot-plug; under backend_mu_
  backends::ScanoutCallback scanout_;
  std::function<void(const Error&)> on_gone_;

  std::atomic<bool> stopping_{false};
  std::atomic<bool> abort_{false};  // the backend's cancel flag: the running request must stop
  std::mutex running_mu_;           // guards running_ against cancel() from the network thread
  std::shared_ptr<CancelFlag> running_;
};

template <class T, class Work, class Done>
void DeviceWorker::request(std::shared_ptr<CancelFlag> cancel, Work work, Done done) {
  boost::asio::post(device_, [this, cancel = std::move(cancel), work = std::move(work), done = std::move(done)]() mutable {
    Result<T> r = begin(cancel) ? work(*backend_) : Result<T>(cancelled_error());
    end();
    if (!r.ok()) report(r.error());
    boost::asio::post(net_, [r = std::move(r), done = std::move(done)]() mutable { done(std::move(r)); });
  });
}

}  // namespace gpubridge::daemon
