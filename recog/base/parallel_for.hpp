// How computation spreads work over threads without owning any: the caller passes a ParallelFor
// that runs fn(context, i) for every i in [0, n) (the pipeline's worker pool, or nothing: then
// the calls run one after another on the calling thread). Every parallel loop writes to separate
// slots per index, so results do not depend on the thread count.
#pragma once

namespace sh {

struct ParallelFor {
  void* pool = nullptr;
  void (*run)(void* pool, int n, void (*fn)(void* context, int index), void* context) = nullptr;

  // Whether the calls can run concurrently (a pool was given).
  bool concurrent() const { return run != nullptr; }

  void operator()(int n, void (*fn)(void* context, int index), void* context) const {
    if (run != nullptr) {
      run(pool, n, fn, context);
    } else {
      for (int i = 0; i < n; ++i) fn(context, i);
    }
  }
};

// A ParallelFor on a pool with ParallelFor(n, fn, context) (the pipeline's WorkerPool).
template <typename Pool>
ParallelFor ParallelOn(Pool* pool) {
  ParallelFor parallel;
  parallel.pool = pool;
  parallel.run = [](void* p, int n, void (*fn)(void*, int), void* c) {
    static_cast<Pool*>(p)->ParallelFor(n, fn, c);
  };
  return parallel;
}

}  // namespace sh
