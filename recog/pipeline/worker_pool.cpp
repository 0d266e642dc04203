#include "recog/pipeline/worker_pool.hpp"

#include <unistd.h>

#include <cstring>

namespace sh {

int OnlineCores() {
  const long n = sysconf(_SC_NPROCESSORS_ONLN);
  if (n < 1) return 1;
  return n > kMaxPoolThreads ? kMaxPoolThreads : static_cast<int>(n);
}

WorkerPool::~WorkerPool() { Stop(); }

Status WorkerPool::Start(int threads) {
  if (threads < 0 || threads > kMaxPoolThreads) {
    return Status::Error(StatusCode::kOutOfRange, "threads = %d outside 0..%d (0: all cores)",
                         threads, kMaxPoolThreads);
  }
  const int wanted = threads == 0 ? OnlineCores() : threads;
  if (wanted == workers_ + 1) return Status::Ok();
  Stop();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = false;
  }
  for (int i = 0; i < wanted - 1; ++i) {
    const int err = pthread_create(&threads_[i], nullptr, &WorkerPool::WorkerMain, this);
    if (err != 0) {
      Stop();
      return Status::Error(StatusCode::kResourceExhausted,
                           "cannot start worker thread %d of %d: %s", i + 1, wanted - 1,
                           std::strerror(err));
    }
    ++workers_;
  }
  return Status::Ok();
}

void WorkerPool::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (int i = 0; i < workers_; ++i) pthread_join(threads_[i], nullptr);
  workers_ = 0;
}

void* WorkerPool::WorkerMain(void* self) {
  WorkerPool& pool = *static_cast<WorkerPool*>(self);
  uint64_t seen = 0;
  while (true) {
    void (*fn)(void*, int) = nullptr;
    void* context = nullptr;
    int n = 0;
    {
      std::unique_lock<std::mutex> lock(pool.mutex_);
      pool.wake_.wait(lock, [&] { return pool.stop_ || pool.generation_ != seen; });
      if (pool.stop_) return nullptr;
      seen = pool.generation_;
      // A worker that wakes after the job was closed has nothing to join.
      if (!pool.open_) continue;
      ++pool.busy_;
      fn = pool.fn_;
      context = pool.context_;
      n = pool.n_;
    }
    pool.RunIndices(fn, context, n);
    {
      std::lock_guard<std::mutex> lock(pool.mutex_);
      --pool.busy_;
    }
    pool.done_.notify_one();
  }
}

void WorkerPool::RunIndices(void (*fn)(void*, int), void* context, int n) {
  for (int i = next_.fetch_add(1); i < n; i = next_.fetch_add(1)) fn(context, i);
}

void WorkerPool::ParallelFor(int n, void (*fn)(void*, int), void* context) {
  if (n <= 0) return;
  if (workers_ == 0 || n == 1) {
    for (int i = 0; i < n; ++i) fn(context, i);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    fn_ = fn;
    context_ = context;
    n_ = n;
    next_.store(0);
    open_ = true;
    ++generation_;
  }
  wake_.notify_all();
  RunIndices(fn, context, n);
  // Every index is taken; wait until the workers that joined have left, then close the job
  // under the same lock, so that no late worker joins it and the next job cannot change the
  // shared index under anyone.
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [&] { return busy_ == 0; });
  open_ = false;
}

}  // namespace sh
