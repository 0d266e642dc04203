// AheadBatch: which items a batch gathers, that each is computed once on whichever thread takes
// it, and which results the search can still take.
#include "recog/base/ahead_batch.hpp"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

namespace sh {
namespace {

struct Squared {
  uint32_t value = 0;
  int computed = 0;  // times computed
  int thread = -1;
};
using Batch = AheadBatch<Squared, 4>;

void Square(void* context, int thread, Batch::Entry& e) {
  ++*static_cast<int*>(context);
  e.result.value = e.index * e.index;
  ++e.result.computed;
  e.result.thread = thread;
}

// A ParallelFor whose calls after the first run on threads of their own.
ParallelFor TwoThreads() {
  ParallelFor parallel;
  parallel.run = [](void*, int n, void (*fn)(void*, int), void* context) {
    std::vector<std::thread> others;
    for (int i = 1; i < n; ++i) others.emplace_back(fn, context, i);
    fn(context, 0);
    for (std::thread& t : others) t.join();
  };
  return parallel;
}

TEST(AheadBatch, GathersTheWantedItemsUpToTheLimits) {
  Batch batch;
  const auto even = [](uint32_t j) { return j % 2 == 0; };
  EXPECT_EQ(batch.Gather(3, 100, 10, even), 4u);  // 3, 4, 6, 8: N = 4 at the most
  EXPECT_EQ(batch.Gather(3, 100, 2, even), 2u);   // 3, 4: `most`
  EXPECT_EQ(batch.Gather(3, 7, 10, even), 3u);    // 3, 4, 6: below `end`
  // One item alone is not kept: the caller computes it.
  EXPECT_EQ(batch.Gather(3, 4, 10, even), 1u);
  EXPECT_EQ(batch.size(), 0u);
  EXPECT_EQ(batch.Find(3), nullptr);
  EXPECT_EQ(batch.Gather(3, 100, 0, even), 1u);  // `most` 0 counts as 1
}

TEST(AheadBatch, ComputesEachItemOnceAndHandsResultsOutInOrder) {
  Batch batch;
  int calls = 0;
  ASSERT_EQ(batch.Gather(5, 100, 4, [](uint32_t j) { return j % 3 != 0; }), 4u);  // 5, 7, 8, 10
  const Squared& first = batch.ComputeAll(TwoThreads(), 2, &Square, &calls);
  EXPECT_EQ(calls, 4);
  EXPECT_EQ(first.value, 25u);
  for (const uint32_t j : {7u, 8u, 10u}) {
    const Squared* r = batch.Find(j);
    ASSERT_NE(r, nullptr) << j;
    EXPECT_EQ(r->value, j * j);
    EXPECT_EQ(r->computed, 1);
    EXPECT_TRUE(r->thread == 0 || r->thread == 1);
  }
  // Passed over: dropped; never gathered: absent.
  EXPECT_EQ(batch.Find(7), nullptr);
  EXPECT_EQ(batch.Find(11), nullptr);
}

TEST(AheadBatch, ItemsPassedOverOrClearedAreGone) {
  Batch batch;
  int calls = 0;
  ASSERT_EQ(batch.Gather(1, 100, 4, [](uint32_t) { return true; }), 4u);  // 1, 2, 3, 4
  (void)batch.ComputeAll(ParallelFor{}, 2, &Square, &calls);              // on the caller alone
  EXPECT_EQ(calls, 4);
  ASSERT_NE(batch.Find(3), nullptr);  // 1 and 2 passed over
  EXPECT_EQ(batch.Find(2), nullptr);
  ASSERT_NE(batch.Find(4), nullptr);
  batch.Clear();
  EXPECT_EQ(batch.Find(4), nullptr);
}

}  // namespace
}  // namespace sh
