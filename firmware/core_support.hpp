// Small helpers the core's files share: its log line, a sleep and a saturating narrowing, and
// the monotonic clock (declared in firmware_core.hpp).
#pragma once

#include <cstdint>

namespace sh::fw {

// One line "stereohash-fw: ..." on stderr (unbuffered: no allocation, one write per message;
// journald adds the time).
void CoreLog(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
// Sleeps ns nanoseconds (nothing for ns <= 0).
void SleepNs(int64_t ns);
// v, or max when v exceeds it.
inline uint32_t Saturate(uint64_t v, uint32_t max) {
  return v > max ? max : static_cast<uint32_t>(v);
}

}  // namespace sh::fw
