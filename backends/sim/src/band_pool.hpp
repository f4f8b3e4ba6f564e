#pragma once
// A fixed set of worker threads that run one job per worker and wait for all of them (a fork/join
// barrier). Worker 0 is the calling thread, so a one-thread pool has no threads and no overhead.
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace gpubridge::sim {

class BandPool {
 public:
  explicit BandPool(unsigned workers);
  ~BandPool();
  BandPool(const BandPool&) = delete;
  BandPool& operator=(const BandPool&) = delete;

  unsigned workers() const { return workers_; }
  // Runs job(w) for every worker w in 0..workers-1 concurrently; returns when all have finished.
  void run(const std::function<void(unsigned)>& job);

 private:
  void loop(unsigned worker);

  unsigned workers_;
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  const std::function<void(unsigned)>* job_ = nullptr;
  std::uint64_t generation_ = 0;
  unsigned running_ = 0;
  bool stop_ = false;
};

}  // namespace gpubridge::sim
