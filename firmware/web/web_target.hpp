// What the commissioning page reads of the firmware and what it may ask of it, behind an
// interface so that the page's rules (login, CSRF, limits) are tested without a running core.
// core_target.hpp implements it over the firmware core.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/canopen/emcy.hpp"
#include "firmware/canopen/nmt.hpp"
#include "firmware/config_keys.hpp"
#include "firmware/firmware_core.hpp"
#include "firmware/fw_config.hpp"
#include "firmware/recorder.hpp"
#include "hal/camera.hpp"
#include "hal/can.hpp"
#include "recog/base/status.hpp"

namespace sh::fw::web {

inline constexpr size_t kMaxEmcyHistory = 16;  // entries of 0x1003 shown

struct WebHealth {
  FirmwareState state = FirmwareState::kInit;
  protocol::NmtState nmt = protocol::NmtState::kPreOperational;
  uint32_t fault_bits = 0;
  uint8_t node_id = 0;
  uint8_t error_register = 0;
  uint32_t heartbeat_ms = 0;
  uint16_t budget_ms = 0;
  uint16_t free_run_dhz = 0;
  uint32_t model_mask = 0;
  hal::CaptureMode capture_mode = hal::CaptureMode::kStereo;
  CoreCounters counters;
  hal::CameraStats camera;
  hal::CanStats can;
  hal::CanBusState can_state = hal::CanBusState::kErrorActive;
  // 0x1003, newest first: error code in the low word, the detail's low 16 bits in the high word.
  uint32_t emcy_history[kMaxEmcyHistory] = {};
  size_t emcy_count = 0;
  bool recording = false;  // a recorder runs (record_dir)
  int record_pending = 0;  // pairs still to record on request
  RecorderCounters recorder;
};

class WebTarget {
 public:
  virtual ~WebTarget() = default;
  virtual WebHealth Health() const = 0;
  virtual Status Trigger() = 0;
  virtual void SetFreeRun(uint16_t rate_dhz) = 0;
  // kFailedPrecondition without a recorder (no record_dir).
  virtual Status RecordNext(int pairs) = 0;
  virtual void ClearFault() = 0;
  // Applies `key` with its value in `config` at run time: true when it took effect now, false
  // when the key takes effect at the next start. An error when the value was refused.
  virtual Result<bool> ApplySetting(ConfigKeyId key, const FwConfig& config) = 0;
};

}  // namespace sh::fw::web
