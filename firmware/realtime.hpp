// Real-time preparation of the process: memory locked and pre-faulted so that the per-trigger
// path takes no page faults, optional SCHED_FIFO for the worker thread.
#pragma once

#include <cstddef>
#include <thread>

#include "recog/base/status.hpp"

namespace sh::fw {

// Deepest stack any firmware thread reached (84 KiB, with the one-camera fallback; 76 to 80 KiB
// in the other runs, the other threads 12 to 56 KiB): the resident part of each thread's stack
// in /proc/PID/smaps of the simulator replaying 1280 x 800 pairs, with the rendered world, with
// the carton database (texture features), with colour parts and with the right camera silent, the
// pre-fault cut to one 16 KiB chunk so that it does not hide the depth; the pages the C library
// keeps at the top of each stack (the thread's control block, its TLS) are included
// (docs/memory.md, "Thread stacks").
inline constexpr size_t kMeasuredStackHighWaterBytes = size_t{84} * 1024;

// Stack bytes each firmware thread touches when it starts, so that an unlocked run takes its
// stack page faults at start rather than in the first trigger: above the measured depth.
inline constexpr size_t kPrefaultStackBytes = size_t{128} * 1024;

// Stack of every thread the firmware starts. The default (the stack rlimit, 8 MiB on Debian) is
// locked in full by LockMemory: seven threads locked 56 MiB, at 1 MiB each 7 MiB, at 512 KiB
// 3.5 MiB. 384 KiB is 4.6 times the measured depth (libcamera's threads on the board, which get
// it too, were not measured here), and the guard page below each stack turns an overflow into a
// crash rather than corruption.
inline constexpr size_t kThreadStackBytes = size_t{384} * 1024;
static_assert(kPrefaultStackBytes >= kMeasuredStackHighWaterBytes, "pre-fault the used depth");
static_assert(kThreadStackBytes >= 4 * kMeasuredStackHighWaterBytes, "4 x margin over the depth");
static_assert(kThreadStackBytes >= 2 * kPrefaultStackBytes, "room above the pre-fault");

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
