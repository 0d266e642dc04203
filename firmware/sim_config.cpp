#include "firmware/sim_config.hpp"

#include <cstring>

#include "hal/sim/world/scene_generator.hpp"

namespace sh::fw {

FwConfig SimDefaults() {
  FwConfig c;
  c.backend = Backend::kSim;
  c.camera = CameraSource::kSim;
  c.calibration[0] = '\0';  // the renderer's rig
  c.lss_store[0] = '\0';    // a desktop simulator keeps no node id
  c.mlock = false;          // nor pins its memory
  // The web page on this machine only, on a port of its own (printed as HTTP_PORT=<n>).
  std::memcpy(c.http_bind, "127.0.0.1", sizeof("127.0.0.1"));
  c.http_port = 0;
  // The box over the rendered table an integrator would configure (render::kTableVolume*).
  c.sim_volume_box = true;
  c.volume_frame = VolumeFrame::kTable;
  std::memcpy(c.volume_min_mm, render::kTableVolumeMinMm, sizeof(c.volume_min_mm));
  std::memcpy(c.volume_max_mm, render::kTableVolumeMaxMm, sizeof(c.volume_max_mm));
  return c;
}

}  // namespace sh::fw
