// How the texture path spreads work over threads without owning any: the caller passes a
// ParallelFor that runs fn(context, i) for every i in [0, n) (the pipeline's worker pool, or
// nothing: then the calls run one after another on the calling thread). Every parallel loop of
// the path writes to separate slots per index, so results do not depend on the thread count.
#pragma once

namespace sh::texture {

struct ParallelFor {
  void* pool = nullptr;
  void (*run)(void* pool, int n, void (*fn)(void* context, int index), void* context) = nullptr;

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

// Bands that row-wise loops are split into (more than threads, so that uneven rows balance).
inline constexpr int kParallelBands = 8;

// Calls body(y_begin, y_end) for kParallelBands bands covering rows [0, height).
template <typename Body>
void ForRowBands(const ParallelFor& parallel, int height, Body&& body) {
  struct Context {
    Body* body;
    int height;
  } context{&body, height};
  parallel(
      kParallelBands,
      [](void* c, int band) {
        auto* ctx = static_cast<Context*>(c);
        const int y0 = ctx->height * band / kParallelBands;
        const int y1 = ctx->height * (band + 1) / kParallelBands;
        if (y1 > y0) (*ctx->body)(y0, y1);
      },
      &context);
}

}  // namespace sh::texture
