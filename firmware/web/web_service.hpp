// The commissioning web page of a running firmware (docs/web.md): its snapshot of the last
// result, which the core feeds as an observer from boot on, and its server, started once the
// core runs. Nothing of it exists when http_bind is empty.
#pragma once

#include <cstdio>
#include <memory>

#include "firmware/firmware_core.hpp"
#include "firmware/fw_config.hpp"
#include "firmware/recorder.hpp"
#include "hal/camera.hpp"
#include "hal/can.hpp"
#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::fw::web {

class WebServiceParts;

class WebService {
 public:
  WebService();
  ~WebService();

  // Before the core starts: the snapshot (nullptr when the page is off), to be one of the
  // core's observers. `out_T_camera` is the output frame's transform.
  Result<CoreObserver*> Prepare(const FwConfig& config, const RigidTransform& out_T_camera);

  struct Running {
    FirmwareCore* core = nullptr;
    const Recorder* recorder = nullptr;  // null without recording
    const hal::CanBus* can = nullptr;
    const hal::StereoCamera* camera = nullptr;
    // The rig for the overlays, or nullptr.
    const StereoCalibration* calibration = nullptr;
    const char* output_frame = "camera";
    const char* config_path = "";  // "" = started without a file
    // The working volume box in the left camera (volume_min_mm..volume_max_mm of the config in
    // this frame), or nullptr when there is no box.
    const RigidTransform* left_T_volume = nullptr;
  };
  // Once the core runs: the password, the server; prints HTTP_PORT=<n> on `announce`.
  Status Start(const FwConfig& config, const Running& running, std::FILE* announce);
  void Stop();

 private:
  std::unique_ptr<WebServiceParts> parts_;
};

}  // namespace sh::fw::web
