// A fixed pool of worker threads for the per-frame work: created once (Start, at the pipeline's
// Init), then each ParallelFor hands out the indices of one job to the workers and the calling
// thread, which all take the next index until none is left. No heap and no thread creation per
// frame; the threads sleep on a condition variable between jobs.
#pragma once

#include <pthread.h>

#include <atomic>
#include <condition_variable>
#include <mutex>

#include "recog/base/status.hpp"

namespace sh {

// Most threads a pool runs, the calling thread included (the board has four cores).
inline constexpr int kMaxPoolThreads = 8;

// The cores the operating system reports online (1 if it cannot tell), at most kMaxPoolThreads.
int OnlineCores();

class WorkerPool {
 public:
  WorkerPool() = default;
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // `threads` in total, the caller included (1: everything runs on the caller, no thread is
  // created); 0 means OnlineCores(). Restarts the pool when the count changes. Errors: a count
  // outside 0..kMaxPoolThreads, or the system refusing a thread (the pool then runs on the
  // caller alone).
  Status Start(int threads);
  void Stop();
  int threads() const { return workers_ + 1; }

  // Calls fn(context, i) for every i in [0, n), spread over the pool; returns when all calls
  // have returned. Calls may run in any order and concurrently: fn must be safe for that.
  void ParallelFor(int n, void (*fn)(void* context, int index), void* context);

 private:
  static void* WorkerMain(void* self);
  void RunIndices(void (*fn)(void*, int), void* context, int n);

  pthread_t threads_[kMaxPoolThreads] = {};
  int workers_ = 0;

  std::mutex mutex_;
  std::condition_variable wake_;  // a new job or stop
  std::condition_variable done_;  // the last worker left the job
  uint64_t generation_ = 0;       // job counter, under mutex_
  bool stop_ = false;             // under mutex_
  int busy_ = 0;                  // workers inside the current job, under mutex_
  bool open_ = false;             // workers may join the current job, under mutex_

  // The current job (under mutex_; workers copy it when they join) and its next index.
  void (*fn_)(void*, int) = nullptr;
  void* context_ = nullptr;
  int n_ = 0;
  std::atomic<int> next_{0};
};

}  // namespace sh
