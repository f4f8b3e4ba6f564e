#pragma once
// A fixed set of worker threads that run one job per worker (a fork/join barrier). start() hands
// the job over and returns at once, so the caller can prepare the next job while this one runs;
// wait() returns when every worker has finished it. A one-worker pool has no threads: start()
// runs the job on the calling thread.
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace gpubridge {

class BandPool {
 public:
  explicit BandPool(unsigned workers);
  ~BandPool();
  BandPool(const BandPool&) = delete;
  BandPool& operator=(const BandPool&) = delete;

  unsigned workers() const { return workers_; }
  // Starts job(w) for every worker w in 0..workers-1 concurrently. The previous job must have been
  // waited for; job must stay alive until wait() returns.
  void start(const std::function<void(unsigned)>& job);
  // Returns when every worker has finished the started job (at once when none is running).
  void wait();

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

}  // namespace gpubridge
