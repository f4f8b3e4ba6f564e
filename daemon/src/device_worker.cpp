#include "gpubridge/daemon/device_worker.hpp"

namespace gpubridge::daemon {

DeviceWorker::DeviceWorker(Executor net, Executor device, std::unique_ptr<backends::Backend> backend)
    : net_(std::move(net)), device_(std::move(device)), backend_(std::move(backend)) {
  backend_->set_cancel_flag(&abort_);
}

DeviceWorker::~DeviceWorker() {
  if (backend_) {
    backend_->set_scanout_callback({});
    backend_->set_cancel_flag(nullptr);
  }
}

void DeviceWorker::set_scanout_callback(backends::ScanoutCallback cb) {
  scanout_ = std::move(cb);
  backend_->set_scanout_callback([this](std::shared_ptr<const backends::ScanoutFrame> f) {
    if (!stopping_.load(std::memory_order_relaxed) && scanout_) scanout_(std::move(f));
  });
}

bool DeviceWorker::begin(const std::shared_ptr<CancelFlag>& cancel) {
  std::lock_guard lock(running_mu_);
  if (stopping_ || (cancel && *cancel)) return false;
  running_ = cancel;
  abort_ = false;
  return true;
}

void DeviceWorker::end() {
  std::lock_guard lock(running_mu_);
  running_.reset();
  abort_ = stopping_.load();
}

void DeviceWorker::cancel(const std::shared_ptr<CancelFlag>& cancel) {
  if (!cancel) return;
  std::lock_guard lock(running_mu_);
  *cancel = true;
  if (running_ == cancel) abort_ = true;
}

void DeviceWorker::stop() {
  std::lock_guard lock(running_mu_);
  stopping_ = true;
  abort_ = true;
}

void DeviceWorker::install(std::unique_ptr<backends::Backend> backend) {
  backend_->set_scanout_callback({});
  backend_->set_cancel_flag(nullptr);
  std::unique_ptr<backends::Backend> old;
  {
    // STATUS reads the mirror's counters from the network thread: swap under the lock and keep
    // what the outgoing mirror counted, so the totals survive an unplug.
    std::lock_guard lock(backend_mu_);
    if (const auto* mirror = dynamic_cast<const MirrorBackend*>(backend_.get()))
      retired_mirror_counters_ += mirror->counters();
    old = std::exchange(backend_, std::move(backend));
  }
  old.reset();  // closing a board may take a while: outside the lock
  backend_->set_cancel_flag(&abort_);
  set_scanout_callback(std::move(scanout_));
}

MirrorCounters DeviceWorker::mirror_counters() const {
  std::lock_guard lock(backend_mu_);
  MirrorCounters total = retired_mirror_counters_;
  if (const auto* mirror = dynamic_cast<const MirrorBackend*>(backend_.get())) total += mirror->counters();
  return total;
}

}  // namespace gpubridge::daemon
