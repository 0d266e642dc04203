// The recogniser's clock for firmware rigs that check poses and allocations: it stands still, so
// the time budget never cuts a search short however slow the build (sanitizers, qemu); a budget
// hit would change both the status and what the sets hold.
#pragma once

#include <cstdint>

#include "recog/pipeline/object_recognizer.hpp"

namespace sh::testing {

inline int64_t ClockStandingStill() { return 0; }

// `config` with the standing clock in place of the board's monotonic one.
inline ObjectRecognizerConfig WithClockStandingStill(ObjectRecognizerConfig config = {}) {
  config.now_ns = &ClockStandingStill;
  return config;
}

}  // namespace sh::testing
