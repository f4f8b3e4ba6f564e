// BandPool (common/include/gpubridge/common/band_pool.hpp): the renderer's fork/join barrier.
// Written for sim-c2t's hand-overs that polled before they slept (tried, not kept: docs/simulator.md,
// "the exact cubes row at two threads"), so they cover both ways a hand-over can go: back-to-back
// jobs (a poller would still be polling), jobs after the workers have surely gone to sleep, and a
// wait() that outlasts a slow worker (whichever it is).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "gpubridge/common/band_pool.hpp"

namespace gpubridge {
namespace {

// Every worker runs every job once, and wait() returns with all their writes done.
void run_jobs(BandPool& pool, unsigned jobs, std::chrono::microseconds pause_between) {
  std::vector<unsigned> runs(pool.workers(), 0);  // each worker writes its own entry only
  std::atomic<unsigned> in_job{0};
  const std::function<void(unsigned)> job = [&](unsigned w) {
    in_job.fetch_add(1);
    ++runs[w];
  };
  for (unsigned j = 1; j <= jobs; ++j) {
    in_job = 0;
    pool.start(job);
    pool.wait();
    ASSERT_EQ(in_job.load(), pool.workers()) << "job " << j;
    for (unsigned w = 0; w < pool.workers(); ++w) ASSERT_EQ(runs[w], j) << "worker " << w << ", job " << j;
    if (pause_between.count() > 0) std::this_thread::sleep_for(pause_between);
  }
}

TEST(SimBandPool, BackToBackJobsRunOncePerWorker) {
  for (unsigned n : {2u, 3u}) {
    BandPool pool(n);
    run_jobs(pool, 3000, std::chrono::microseconds(0));
  }
}

TEST(SimBandPool, JobsAfterTheWorkersSleptRunOncePerWorker) {
  BandPool pool(2);
  // Long enough for the workers to sleep: every job wakes them.
  run_jobs(pool, 20, std::chrono::microseconds(200));
}

// wait() returns only after the slowest worker, whichever it is (a wait of 1 ms: past any poll).
TEST(SimBandPool, WaitOutlastsASlowWorker) {
  for (unsigned n : {2u, 3u})
    for (unsigned slow = 0; slow < n; ++slow) {
      BandPool pool(n);
      std::atomic<bool> slow_done{false};
      const std::function<void(unsigned)> job = [&](unsigned w) {
        if (w != slow) return;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        slow_done = true;
      };
      pool.start(job);
      pool.wait();
      EXPECT_TRUE(slow_done.load()) << n << " workers, slow worker " << slow;
    }
}

TEST(SimBandPool, OneWorkerRunsTheJobOnTheCallingThread) {
  BandPool pool(1);
  std::thread::id ran;
  const std::function<void(unsigned)> job = [&](unsigned) { ran = std::this_thread::get_id(); };
  pool.start(job);
  EXPECT_EQ(ran, std::this_thread::get_id());
  pool.wait();
}

}  // namespace
}  // namespace gpubridge
