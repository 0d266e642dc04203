// The texture path's parallel loops: the ParallelFor of recog/base (the pipeline's worker pool,
// or nothing: the calls then run one after another on the calling thread), and row bands over it.
#pragma once

#include "recog/base/parallel_for.hpp"

namespace sh::texture {

using ::sh::ParallelFor;
using ::sh::ParallelOn;

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
