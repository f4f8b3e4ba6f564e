#pragma once
// A fixed set of worker threads that run one job per worker (a fork/join barrier). start() hands
// the job over and returns at once, so the caller can prepare the next job while this one runs;
// wait() returns when every worker has finished it. A one-worker pool has no threads: start()
// runs the job on the calling thread.
//
// Hand-overs spin briefly instead of sleeping where a sleep would sit on the critical path: a
// sleeping thread takes 15-20 us to wake on this project's 2-vCPU VM (the wake-up of a halted
// vCPU), and the cubes' two-thread frame has three batches, so three hand-overs each way
// (docs/simulator.md, "the exact cubes row at two threads"). The caller sleeps while every worker
// still works (spinning then would take a core from one of them) and spins once one has finished;
// the last worker to finish spins for the next job (the caller hands it over within microseconds
// when it is spinning); an earlier finisher sleeps, leaving its core to the caller. Every spin is
// bounded, then sleeps, and yields the core between polls: with PAUSE alone the fan at two threads
// ran 5-8 % slower than main at load 7 (other helpers' builds), the spinning thread taking time
// the drawing ones needed.
#include <atomic>
#include <chrono>
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

  // How long the caller spins for the last workers once one has finished, and the last finisher
  // for the next job, before sleeping.
  static constexpr std::chrono::microseconds kCallerSpin{200}, kWorkerSpin{50};

 private:
  void loop(unsigned worker);
  // Waits for a generation other than `seen` (spinning first if `spin`); false when stopping.
  bool await_job(std::uint64_t seen, bool spin);
  // A worker finished the job: wakes the caller if it sleeps and this was the first or last
  // finisher. True for the last.
  bool finished();

  unsigned workers_;
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  const std::function<void(unsigned)>* job_ = nullptr;  // written before generation_ is raised
  std::atomic<std::uint64_t> generation_{0};
  std::atomic<unsigned> running_{0};
  // Who sleeps on start_ / done_ (or is about to, under mutex_): the other side notifies only then.
  // Sequentially consistent with generation_ and running_, so one of the two always sees the other.
  std::atomic<unsigned> sleeping_workers_{0};
  std::atomic<bool> caller_sleeping_{false};
  std::atomic<bool> stop_{false};
};

}  // namespace gpubridge
