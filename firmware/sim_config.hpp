// The simulator's configuration defaults (`stereohash-fw-sim` without a file). They depend on the
// simulated world (the box over its rendered table), so they are part of the simulator program's
// library, never of the board program.
#pragma once

#include "firmware/fw_config.hpp"

namespace sh::fw {

FwConfig SimDefaults();

}  // namespace sh::fw
