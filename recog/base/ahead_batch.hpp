// Work done ahead of its turn on the caller's threads: a search that takes its items (scene
// bases) one at a time, in increasing order, computes the next few at once, spread over the
// threads of a ParallelFor, and takes each result when its turn comes. A result holds only
// while what it was computed from is unchanged: the owner calls Clear() whenever that changes.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>

#include "recog/base/parallel_for.hpp"

namespace sh {

template <typename Result, uint32_t N>
class AheadBatch {
  static_assert(N >= 1, "a batch holds one item at least");

 public:
  struct Entry {
    uint32_t index = 0;  // the item's place in the owner's order
    Result result;
  };
  // compute(context, thread, entry): fills entry.result for entry.index; `thread` is the call's
  // index in [0, threads), so that each thread works in its own scratch.
  using Compute = void (*)(void* context, int thread, Entry& entry);

  // Drops every result.
  void Clear() { count_ = next_ = 0; }

  // The result of item `index` when the batch holds it, else null. Items are asked for in
  // increasing order: the results of the items passed over are dropped.
  const Result* Find(uint32_t index) {
    while (next_ < count_ && entries_[next_].index < index) ++next_;
    return next_ < count_ && entries_[next_].index == index ? &entries_[next_].result : nullptr;
  }

  // Starts a batch of item `first` and the next items j in (first, end) for which wanted(j):
  // `most` items in all at the most, and N. Returns their number; with one, nothing is kept
  // (the caller computes it alone, on its own thread).
  template <typename Wanted>
  uint32_t Gather(uint32_t first, uint32_t end, uint32_t most, Wanted&& wanted) {
    const uint32_t batch = std::min(N, std::max(most, 1u));
    Clear();
    entries_[count_++].index = first;
    for (uint32_t j = first + 1; j < end && count_ < batch; ++j) {
      if (wanted(j)) entries_[count_++].index = j;
    }
    const uint32_t gathered = count_;
    if (gathered == 1) Clear();
    return gathered;
  }

  // Computes every item gathered, on min(threads, items) calls of `parallel`. Each call takes the
  // next item no call has taken until none is left: items differ in cost (a vote's grows with the
  // features near its basis), and a fixed share would leave a thread idle at the end. Returns the
  // first item's result.
  const Result& ComputeAll(const ParallelFor& parallel, int threads, Compute compute,
                           void* context) {
    compute_ = compute;
    context_ = context;
    taken_.store(0, std::memory_order_relaxed);
    parallel(std::min(threads, static_cast<int>(count_)), &AheadBatch::TakeUntilNoneLeft, this);
    return entries_[0].result;
  }

  uint32_t size() const { return count_; }

 private:
  static void TakeUntilNoneLeft(void* self, int thread) {
    auto& b = *static_cast<AheadBatch*>(self);
    for (uint32_t k = b.taken_.fetch_add(1, std::memory_order_relaxed); k < b.count_;
         k = b.taken_.fetch_add(1, std::memory_order_relaxed)) {
      b.compute_(b.context_, thread, b.entries_[k]);
    }
  }

  Entry entries_[N];
  uint32_t count_ = 0;  // entries_[0 .. count_) gathered
  uint32_t next_ = 0;   // entries_[next_ ..) not passed over yet
  // While ComputeAll runs: the next entry no call has taken, and what computes it.
  std::atomic<uint32_t> taken_{0};
  Compute compute_ = nullptr;
  void* context_ = nullptr;
};

}  // namespace sh
