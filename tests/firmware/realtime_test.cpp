// The firmware's thread stacks: bounded (mlock locks each one in full) and still deep enough.
#include "firmware/realtime.hpp"

#include <gtest/gtest.h>
#include <pthread.h>

#include <cstring>
#include <thread>

namespace sh::fw {
namespace {

// ThreadSanitizer replaces thread creation and keeps part of each stack: it refuses stacks below
// about 1 MiB and the pre-fault overflows the firmware's. The stack tests say so and skip there.
#if defined(__SANITIZE_THREAD__)
#define SH_SKIP_UNDER_THREAD_SANITIZER() \
  GTEST_SKIP() << "ThreadSanitizer changes thread stacks; this test runs in the other builds"
#else
#define SH_SKIP_UNDER_THREAD_SANITIZER() (void)0
#endif

size_t StackOfNewThread() {
  size_t bytes = 0;
  std::thread t([&bytes] {
    pthread_attr_t attr;
    if (pthread_getattr_np(pthread_self(), &attr) != 0) return;
    (void)pthread_attr_getstacksize(&attr, &bytes);
    (void)pthread_attr_destroy(&attr);
  });
  t.join();
  return bytes;
}

TEST(ThreadStacks, LaterThreadsGetTheGivenSize) {
  SH_SKIP_UNDER_THREAD_SANITIZER();
  const size_t before = StackOfNewThread();
  ASSERT_TRUE(LimitThreadStacks(size_t{768} * 1024).ok());
  EXPECT_EQ(StackOfNewThread(), size_t{768} * 1024);
  ASSERT_TRUE(LimitThreadStacks().ok());
  EXPECT_EQ(StackOfNewThread(), kThreadStackBytes);
  EXPECT_NE(before, kThreadStackBytes);  // the C library's default was a different size
}

TEST(ThreadStacks, TheFirmwareStackHoldsThePrefault) {
  SH_SKIP_UNDER_THREAD_SANITIZER();
  ASSERT_TRUE(LimitThreadStacks().ok());
  static_assert(kThreadStackBytes >= 2 * kPrefaultStackBytes, "room above the pre-fault");
  bool done = false;
  std::thread t([&done] {
    PrefaultStack();
    done = true;
  });
  t.join();
  EXPECT_TRUE(done);
}

TEST(ThreadStacks, ATooSmallStackIsRefusedWithTheSize) {
  SH_SKIP_UNDER_THREAD_SANITIZER();
  ASSERT_TRUE(LimitThreadStacks().ok());
  const Status s = LimitThreadStacks(16);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(std::strstr(s.message(), "16"), nullptr) << s.message();
  EXPECT_EQ(StackOfNewThread(), kThreadStackBytes);  // the previous setting stays
}

}  // namespace
}  // namespace sh::fw
