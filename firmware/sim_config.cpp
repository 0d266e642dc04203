// The simulator's configuration defaults: they depend on the simulated world (its rendered
// table), so they live with the simulator program, not in the board's configuration code.
#include <cstring>

#include "firmware/fw_config.hpp"
#include "hal/sim/world/scene_generator.hpp"

namespace sh::fw {

FwConfig SimDefaults() {
  FwConfig c;
  c.backend = Backend::kSim;
  c.calibration_path[0] = '\0';  // the renderer's rig
  c.mlock = false;               // a desktop simulator need not pin its memory
  // The box over the rendered table an integrator would configure (render::kTableVolume*).
  c.volume_set = true;
  c.volume_is_sim_default = true;
  c.volume_in_table_frame = true;
  std::memcpy(c.volume_min_mm, render::kTableVolumeMinMm, sizeof(c.volume_min_mm));
  std::memcpy(c.volume_max_mm, render::kTableVolumeMaxMm, sizeof(c.volume_max_mm));
  return c;
}

}  // namespace sh::fw
