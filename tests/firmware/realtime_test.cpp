// The firmware's thread stacks: bounded (mlock locks each one in full) and still deep enough;
// what LockMemory locks.
#include "firmware/realtime.hpp"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sys/mman.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <thread>

namespace sh::fw {
namespace {

// Which sanitizer this build has: GCC defines __SANITIZE_*__, clang answers __has_feature.
#if defined(__SANITIZE_THREAD__)
#define SH_THREAD_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define SH_THREAD_SANITIZER 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define SH_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SH_ADDRESS_SANITIZER 1
#endif
#endif

// ThreadSanitizer replaces thread creation and keeps part of each stack: it refuses stacks below
// about 1 MiB and the pre-fault overflows the firmware's. The stack tests say so and skip there.
#if defined(SH_THREAD_SANITIZER)
#define SH_SKIP_UNDER_THREAD_SANITIZER() \
  GTEST_SKIP() << "ThreadSanitizer changes thread stacks; this test runs in the other builds"
#else
#define SH_SKIP_UNDER_THREAD_SANITIZER() (void)0
#endif

// AddressSanitizer and ThreadSanitizer intercept mlock and mlockall and make them no-ops that
// report success (locking would pin their shadow memory): what is locked cannot be checked there.
#if defined(SH_ADDRESS_SANITIZER) || defined(SH_THREAD_SANITIZER)
#define SH_SKIP_UNDER_SANITIZER_LOCKS() \
  GTEST_SKIP() << "the sanitizer's mlockall locks nothing; this test runs in the other builds"
#else
#define SH_SKIP_UNDER_SANITIZER_LOCKS() (void)0
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

// The "Locked:" KiB of the mapping that holds `address`, from /proc/self/smaps; -1 if none.
long LockedKibAt(const void* address) {
  std::FILE* f = std::fopen("/proc/self/smaps", "r");
  if (f == nullptr) return -1;
  const auto at = reinterpret_cast<uintptr_t>(address);
  bool inside = false;
  long locked = -1;
  char line[512];
  while (std::fgets(line, sizeof(line), f) != nullptr) {
    unsigned long lo = 0;
    unsigned long hi = 0;
    if (std::sscanf(line, "%lx-%lx ", &lo, &hi) == 2 && std::strchr(line, ':') != nullptr &&
        std::strncmp(line, "Locked:", 7) != 0) {
      inside = at >= lo && at < hi;
    } else if (inside && std::sscanf(line, "Locked: %ld kB", &locked) == 1) {
      break;
    }
  }
  std::fclose(f);
  return inside ? locked : -1;
}

// LockMemory locks what is mapped when it is called, every page of it, and nothing mapped later
// (no MCL_FUTURE): the firmware calls it once its per-frame buffers exist.
TEST(LockMemory, LocksTheCurrentMappingsOnly) {
  SH_SKIP_UNDER_SANITIZER_LOCKS();
  constexpr size_t kBytes = size_t{4} << 20;
  auto* map_anonymous = +[](size_t bytes) {
    return mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  };
  void* before = map_anonymous(kBytes);  // never touched
  ASSERT_NE(before, MAP_FAILED);
  const Status s = LockMemory();
  if (!s.ok()) {
    (void)munmap(before, kBytes);
    GTEST_SKIP() << s.message() << " (no permission to lock here)";
  }
  void* after = map_anonymous(kBytes);
  ASSERT_NE(after, MAP_FAILED);
  static_cast<volatile char*>(after)[0] = 1;
  const long locked_before = LockedKibAt(before);
  const long locked_after = LockedKibAt(after);
  (void)munlockall();
  (void)munmap(before, kBytes);
  (void)munmap(after, kBytes);
  EXPECT_GE(locked_before, static_cast<long>(kBytes / 1024)) << "faulted in and locked in full";
  EXPECT_EQ(locked_after, 0) << "a mapping made after the call is not locked";
}

TEST(ThreadStacks, LaterThreadsGetTheGivenSize) {
  SH_SKIP_UNDER_THREAD_SANITIZER();
  const size_t before = StackOfNewThread();
  // Smaller than the firmware's: the C library reuses a freed stack for a new thread when it is
  // at least as large as asked (up to four times), and reports the reused stack's size.
  ASSERT_TRUE(LimitThreadStacks(kThreadStackBytes / 2).ok());
  EXPECT_EQ(StackOfNewThread(), kThreadStackBytes / 2);
  ASSERT_TRUE(LimitThreadStacks().ok());
  EXPECT_EQ(StackOfNewThread(), kThreadStackBytes);
  EXPECT_NE(before, kThreadStackBytes);  // the C library's default was a different size
}

// A thread of the firmware's stack size takes the pre-fault, and four times the deepest stack
// measured (an overflow would hit the guard page and crash the test).
TEST(ThreadStacks, TheFirmwareStackHoldsThePrefaultAndFourTimesTheMeasuredDepth) {
  SH_SKIP_UNDER_THREAD_SANITIZER();
  ASSERT_TRUE(LimitThreadStacks().ok());
  int done = 0;
  std::thread t([&done] {
    PrefaultStack();
    ++done;
    PrefaultStack(4 * kMeasuredStackHighWaterBytes);
    ++done;
  });
  t.join();
  EXPECT_EQ(done, 2);
  EXPECT_EQ(StackOfNewThread(), kThreadStackBytes);
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
