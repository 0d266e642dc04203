#include "firmware/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

namespace sh::fw {

Status LockMemory() {
  if (mlockall(MCL_CURRENT) != 0) {
    return Status::Error(StatusCode::kUnavailable,
                         "mlockall failed: %s (raise LimitMEMLOCK or grant CAP_IPC_LOCK)",
                         std::strerror(errno));
  }
  return Status::Ok();
}

Status LimitThreadStacks(size_t bytes) {
  pthread_attr_t attr;
  int rc = pthread_attr_init(&attr);
  if (rc == 0) {
    rc = pthread_attr_setstacksize(&attr, bytes);
    // A GNU extension (glibc 2.18): the attributes of threads created without any, as
    // std::thread creates them.
    if (rc == 0) rc = pthread_setattr_default_np(&attr);
    (void)pthread_attr_destroy(&attr);
  }
  if (rc != 0) {
    return Status::Error(StatusCode::kUnavailable, "thread stack size %zu refused: %s", bytes,
                         std::strerror(rc));
  }
  return Status::Ok();
}

// noinline keeps the array in this frame; volatile keeps the writes.
__attribute__((noinline)) void PrefaultStack(size_t bytes) {
  constexpr size_t kChunk = size_t{16} * 1024;
  volatile unsigned char chunk[kChunk];
  for (size_t i = 0; i < kChunk; i += 4096) chunk[i] = 0;
  if (bytes > kChunk) PrefaultStack(bytes - kChunk);
  chunk[0] = chunk[kChunk - 1];
}

Status SetFifoPriority(std::thread& thread, int priority) {
  sched_param param{};
  param.sched_priority = priority;
  const int rc = pthread_setschedparam(thread.native_handle(), SCHED_FIFO, &param);
  if (rc != 0) {
    return Status::Error(StatusCode::kUnavailable, "SCHED_FIFO %d refused: %s", priority,
                         std::strerror(rc));
  }
  return Status::Ok();
}

}  // namespace sh::fw
