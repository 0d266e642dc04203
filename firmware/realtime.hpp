// Real-time preparation of the process: memory locked and pre-faulted so that the per-trigger
// path takes no page faults, optional SCHED_FIFO for the worker thread.
#pragma once

#include <cstddef>
#include <thread>

#include "recog/base/status.hpp"

namespace sh::fw {

// Stack bytes each firmware thread touches when it starts (the pipeline's deepest call chain
// stays far below this; see docs/firmware.md).
inline constexpr size_t kPrefaultStackBytes = size_t{256} * 1024;

// mlockall(MCL_CURRENT | MCL_FUTURE). kUnavailable with the reason when not permitted
// (RLIMIT_MEMLOCK, no CAP_IPC_LOCK); the caller logs it and runs on.
Status LockMemory();

// Touches `bytes` of the calling thread's stack so that the pages are mapped (and, after
// LockMemory, locked) before the first trigger.
void PrefaultStack(size_t bytes = kPrefaultStackBytes);

// SCHED_FIFO at `priority` (1..99) for `thread`; kUnavailable when not permitted.
Status SetFifoPriority(std::thread& thread, int priority);

}  // namespace sh::fw
