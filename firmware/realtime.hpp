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

// Stack of every thread the firmware starts. The default (the stack rlimit, 8 MiB on Debian) is
// locked in full by LockMemory: seven threads locked 56 MiB. The deepest thread touches at most
// 264 KiB including the kPrefaultStackBytes pre-fault (measured per thread from
// /proc/PID/smaps, docs/memory.md); 1 MiB leaves four times that, and the guard page below each
// stack turns an overflow into a crash rather than corruption.
inline constexpr size_t kThreadStackBytes = size_t{1} << 20;

// Makes `bytes` the stack size of the threads created afterwards (std::thread included), for the
// whole process. kUnavailable with the reason when the C library refuses.
Status LimitThreadStacks(size_t bytes = kThreadStackBytes);

// mlockall(MCL_CURRENT): faults in and locks every page mapped now (static storage, the heap,
// the blocks taken at Init, every thread's whole stack, the program and its libraries); pages
// mapped later are not locked (no MCL_FUTURE), so the caller locks after start-up, once every
// buffer of the per-frame path exists, and again after anything that maps new ones (a reload of
// the model data, a camera restart). kUnavailable with the reason when not permitted
// (RLIMIT_MEMLOCK, no CAP_IPC_LOCK); the caller logs it and runs on.
Status LockMemory();

// Touches `bytes` of the calling thread's stack so that the pages are mapped before the first
// trigger (LockMemory, once the threads run, locks each stack in full whether touched or not).
void PrefaultStack(size_t bytes = kPrefaultStackBytes);

// SCHED_FIFO at `priority` (1..99) for `thread`; kUnavailable when not permitted.
Status SetFifoPriority(std::thread& thread, int priority);

}  // namespace sh::fw
