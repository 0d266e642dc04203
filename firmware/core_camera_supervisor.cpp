// The camera's supervision: restarts after a failed capture, the fall back to one camera when
// the other stays silent, and the return to stereo when it is back.
#include "firmware/core_support.hpp"
#include "firmware/firmware_core.hpp"
#include "firmware/realtime.hpp"

namespace sh::fw {

using namespace sh::protocol;

bool FirmwareCore::RestartCamera(hal::CaptureMode mode) {
  if (camera_started_) (void)dev_.camera->Stop();
  camera_started_ = false;
  Status s = dev_.camera->SetCaptureMode(mode);
  if (s.ok()) s = dev_.camera->Start();
  if (!s.ok()) {
    CoreLog("camera restart (%s): %s", hal::CaptureModeName(mode), s.message());
    return false;
  }
  camera_started_ = true;
  capture_mode_ = mode;
  // Not locked here: a clear-fault or a fallback may restart twice, so each locks once when it
  // is done (LockCurrentMemory), and boot locks after its threads start.
  return true;
}

void FirmwareCore::LockCurrentMemory() {
  if (!config_.lock_memory) return;
  const Status s = LockMemory();
  // The refusal is logged once, whichever thread meets it first.
  if (!s.ok() && !lock_refusal_logged_.exchange(true))
    CoreLog("%s; continuing unlocked", s.message());
}

bool FirmwareCore::FallBackToOneCamera(const Status& failure) {
  if (capture_mode_.load() != hal::CaptureMode::kStereo || !dev_.recognition->monocular() ||
      failure.code() != StatusCode::kDeadlineExceeded) {
    return false;
  }
  const Result<hal::StereoSide> silent = dev_.camera->SilentSide();
  if (!silent.ok()) return false;
  const uint64_t timeouts = dev_.camera->stats().timeouts;
  const bool left_failed = *silent == hal::StereoSide::kLeft;
  const hal::CaptureMode working =
      left_failed ? hal::CaptureMode::kRightOnly : hal::CaptureMode::kLeftOnly;
  if (!RestartCamera(working)) {
    // The other camera does not start alone either: stereo as before, and the capture fault.
    (void)RestartCamera(hal::CaptureMode::kStereo);
    LockCurrentMemory();  // the buffers of this start
    return false;
  }
  LockCurrentMemory();  // the buffers of this start
  CoreLog("%s; continuing with the %s camera alone (monocular results)", failure.message(),
          left_failed ? "right" : "left");
  // A warning, not a fault: triggers are answered, each set with the monocular status.
  SendEmcyFrame(canopen_.Raise(
      kWarningOneCamera, static_cast<uint16_t>(EmcyCode::kSensor),
      kSensorOneCamera | (left_failed ? 0u : 1u) << 16 | Saturate(timeouts, 0xFFFF)));
  return true;
}

bool FirmwareCore::StartOnOneCamera(const Status& failure) {
  if (!dev_.recognition->monocular()) return false;
  for (const hal::CaptureMode mode : {hal::CaptureMode::kLeftOnly, hal::CaptureMode::kRightOnly}) {
    if (!RestartCamera(mode)) continue;
    const bool left_failed = mode == hal::CaptureMode::kRightOnly;
    CoreLog("camera start failed: %s; continuing with the %s camera alone (monocular results)",
            failure.message(), left_failed ? "right" : "left");
    SendEmcyFrame(canopen_.Raise(kWarningOneCamera, static_cast<uint16_t>(EmcyCode::kSensor),
                                 kSensorOneCamera | (left_failed ? 0u : 1u) << 16));
    return true;
  }
  // Neither camera starts alone: the next start is in stereo again (capture_mode_ changes only
  // when a start succeeds, so it still says stereo).
  (void)dev_.camera->SetCaptureMode(hal::CaptureMode::kStereo);
  return false;
}

bool FirmwareCore::TryStereoAgain() {
  const hal::CaptureMode one = capture_mode_.load();
  if (RestartCamera(hal::CaptureMode::kStereo)) {
    // The failed camera is back when a pair arrives.
    hal::StereoFrame probe;
    const Status s = dev_.camera->Capture(&probe, config_.capture_timeout_ms);
    dev_.camera->Release();
    if (s.ok()) return true;
    CoreLog("stereo again: %s", s.message());
  }
  (void)RestartCamera(one);
  return false;
}

}  // namespace sh::fw
