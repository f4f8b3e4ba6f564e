#include "gpubridge/common/band_pool.hpp"

namespace gpubridge {

BandPool::BandPool(unsigned workers) : workers_(workers == 0 ? 1 : workers) {
  if (workers_ > 1)
    for (unsigned w = 0; w < workers_; ++w) threads_.emplace_back([this, w] { loop(w); });
}

BandPool::~BandPool() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  start_.notify_all();
  for (auto& t : threads_) t.join();
}

void BandPool::start(const std::function<void(unsigned)>& job) {
  if (workers_ == 1) {
    job(0);
    return;
  }
  {
    std::lock_guard lock(mutex_);
    job_ = &job;
    running_ = workers_;
    ++generation_;
  }
  start_.notify_all();
}

void BandPool::wait() {
  if (workers_ == 1) return;
  std::unique_lock lock(mutex_);
  done_.wait(lock, [this] { return running_ == 0; });
  job_ = nullptr;
}

void BandPool::loop(unsigned worker) {
  std::uint64_t seen = 0;
  for (;;) {
    const std::function<void(unsigned)>* job = nullptr;
    {
      std::unique_lock lock(mutex_);
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      job = job_;
    }
    (*job)(worker);
    {
      std::lock_guard lock(mutex_);
      if (--running_ == 0) done_.notify_one();
    }
  }
}

}  // namespace gpubridge
