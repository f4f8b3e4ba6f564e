#include "gpubridge/common/band_pool.hpp"

namespace gpubridge {

namespace {
// One step of a spin: tells the core this is a wait loop (x86 PAUSE).
inline void spin_pause() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

// Spins until done() or `limit` has passed; returns done().
template <class Done>
bool spin_until(Done done, std::chrono::microseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  for (;;) {
    for (int i = 0; i < 8; ++i) {  // the clock read is dearer than a poll of one line
      if (done()) return true;
      spin_pause();
    }
    std::this_thread::yield();  // any other thread ready on this core runs first (the machine's load)
    if (std::chrono::steady_clock::now() >= end) return done();
  }
}
}  // namespace

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
  job_ = &job;
  running_.store(workers_);
  generation_.fetch_add(1);  // releases job_ and running_ to the workers
  if (sleeping_workers_.load() != 0) {
    // Taken and released: a worker between its check and its wait holds the mutex, so the notify
    // cannot fall between the two.
    { std::lock_guard lock(mutex_); }
    start_.notify_all();
  }
}

void BandPool::wait() {
  if (workers_ == 1) return;
  if (running_.load() == 0) return;
  auto sleep_until = [&](unsigned at_most) {
    std::unique_lock lock(mutex_);
    caller_sleeping_.store(true);
    done_.wait(lock, [&] { return running_.load() <= at_most; });
    caller_sleeping_.store(false);
  };
  // Every worker still drawing: sleep until the first one finishes.
  if (running_.load() == workers_) sleep_until(workers_ - 1);
  // Then the others are close behind (the cuts balance the work): spin, then sleep.
  if (!spin_until([&] { return running_.load() == 0; }, kCallerSpin)) sleep_until(0);
  job_ = nullptr;
}

bool BandPool::finished() {
  const unsigned left = running_.fetch_sub(1) - 1;
  if ((left == 0 || left == workers_ - 1) && caller_sleeping_.load()) {
    { std::lock_guard lock(mutex_); }
    done_.notify_one();
  }
  return left == 0;
}

bool BandPool::await_job(std::uint64_t seen, bool spin) {
  auto ready = [&] { return stop_.load() || generation_.load() != seen; };
  if (!(spin && spin_until(ready, kWorkerSpin))) {
    std::unique_lock lock(mutex_);
    sleeping_workers_.fetch_add(1);
    start_.wait(lock, ready);
    sleeping_workers_.fetch_sub(1);
  }
  return !stop_.load();
}

void BandPool::loop(unsigned worker) {
  std::uint64_t seen = 0;
  bool last = false;  // this worker finished the previous job last: its caller is about to start the next
  for (;;) {
    if (!await_job(seen, last)) return;
    seen = generation_.load();
    (*job_)(worker);
    last = finished();
  }
}

}  // namespace gpubridge
