#include "recog/pipeline/worker_pool.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>

#include "tests/support/counting_allocator.hpp"

namespace sh {
namespace {

struct Counts {
  std::atomic<int> calls[64];
  std::atomic<int> total{0};
};

void Count(void* context, int i) {
  Counts& c = *static_cast<Counts*>(context);
  c.calls[i].fetch_add(1);
  c.total.fetch_add(1);
}

TEST(WorkerPool, EveryIndexRunsExactlyOnce) {
  for (int threads : {1, 2, 3, 4}) {
    WorkerPool pool;
    ASSERT_TRUE(pool.Start(threads).ok());
    EXPECT_EQ(pool.threads(), threads);
    for (int round = 0; round < 300; ++round) {
      const int n = 1 + round % 64;
      Counts counts;
      for (auto& c : counts.calls) c.store(0);
      pool.ParallelFor(n, &Count, &counts);
      ASSERT_EQ(counts.total.load(), n) << threads << " threads, round " << round;
      for (int i = 0; i < n; ++i) ASSERT_EQ(counts.calls[i].load(), 1) << i;
    }
  }
}

// Two slow calls on two threads overlap: both start before either ends.
struct Overlap {
  std::atomic<int> started{0};
  std::atomic<bool> saw_both{false};
};

void WaitForTheOther(void* context, int) {
  Overlap& o = *static_cast<Overlap*>(context);
  o.started.fetch_add(1);
  for (long spin = 0; spin < 200000000L && o.started.load() < 2; ++spin) {
  }
  if (o.started.load() == 2) o.saw_both.store(true);
}

TEST(WorkerPool, TwoThreadsRunConcurrently) {
  WorkerPool pool;
  ASSERT_TRUE(pool.Start(2).ok());
  Overlap o;
  pool.ParallelFor(2, &WaitForTheOther, &o);
  EXPECT_TRUE(o.saw_both.load());
}

TEST(WorkerPool, NoHeapPerJob) {
  WorkerPool pool;
  ASSERT_TRUE(pool.Start(3).ok());
  Counts counts;
  for (auto& c : counts.calls) c.store(0);
  pool.ParallelFor(8, &Count, &counts);  // warm-up
  const uint64_t before = testing::HeapAllocations();
  for (int round = 0; round < 100; ++round) pool.ParallelFor(16, &Count, &counts);
  EXPECT_EQ(testing::HeapAllocations(), before);
}

TEST(WorkerPool, StartChecksTheCountAndRestarts) {
  WorkerPool pool;
  const Status bad = pool.Start(kMaxPoolThreads + 1);
  EXPECT_EQ(bad.code(), StatusCode::kOutOfRange);
  EXPECT_NE(std::strstr(bad.message(), "threads"), nullptr);
  EXPECT_FALSE(pool.Start(-1).ok());
  ASSERT_TRUE(pool.Start(0).ok());  // all online cores
  EXPECT_EQ(pool.threads(), OnlineCores());
  ASSERT_TRUE(pool.Start(3).ok());
  EXPECT_EQ(pool.threads(), 3);
  ASSERT_TRUE(pool.Start(1).ok());
  EXPECT_EQ(pool.threads(), 1);
  Counts counts;
  for (auto& c : counts.calls) c.store(0);
  pool.ParallelFor(0, &Count, &counts);
  EXPECT_EQ(counts.total.load(), 0);
  pool.ParallelFor(5, &Count, &counts);
  EXPECT_EQ(counts.total.load(), 5);
}

}  // namespace
}  // namespace sh
