#include "firmware/web/core_target.hpp"

namespace sh::fw::web {

WebHealth CoreTarget::Health() const {
  WebHealth h;
  h.state = core_->state();
  h.nmt = core_->nmt_state();
  h.fault_bits = core_->fault_bits();
  h.node_id = core_->node_id();
  h.error_register = static_cast<uint8_t>(core_->canopen().Get(0x1001, 0));
  h.heartbeat_ms = core_->heartbeat_ms();
  h.budget_ms = core_->budget_ms();
  h.free_run_dhz = core_->free_run_dhz();
  h.model_mask = core_->model_mask();
  h.capture_mode = core_->capture_mode();
  h.counters = core_->counters();
  h.camera = camera_->stats();
  h.can = can_->stats();
  h.can_state = can_->state();
  const uint32_t n = core_->canopen().Get(0x1003, 0);
  h.emcy_count = n < kMaxEmcyHistory ? n : kMaxEmcyHistory;
  for (size_t i = 0; i < h.emcy_count; ++i) {
    h.emcy_history[i] = core_->canopen().Get(0x1003, static_cast<uint8_t>(i + 1));
  }
  h.recording = core_->recording();
  h.record_pending = core_->record_pending();
  if (recorder_ != nullptr) h.recorder = recorder_->counters();
  return h;
}

Status CoreTarget::RecordNext(int pairs) {
  if (!core_->recording()) {
    return Status::Error(StatusCode::kFailedPrecondition,
                         "no recording: record_dir is not set (or not writable)");
  }
  core_->RecordNext(pairs);
  return Status::Ok();
}

Result<bool> CoreTarget::ApplySetting(ConfigKeyId key, const FwConfig& c) {
  switch (key) {
    case ConfigKeyId::budget_ms:
      core_->SetTimeBudget(c.budget_ms);
      return true;
    case ConfigKeyId::free_run_dhz:
      core_->SetFreeRunRate(c.free_run_dhz);
      return true;
    case ConfigKeyId::heartbeat_ms:
      core_->SetHeartbeat(static_cast<uint16_t>(c.heartbeat_ms));
      return true;
    case ConfigKeyId::model_mask: {
      // As at boot: the mask is cut to the loaded models.
      const size_t n = core_->loaded_models();
      const uint32_t loaded = n >= 32 ? 0xFFFFFFFFu : (1u << n) - 1;
      SH_RETURN_IF_ERROR(
          core_->SelectModels(c.model_mask & loaded).WithContext("key 'model_mask'"));
      return true;
    }
    default:
      return false;
  }
}

}  // namespace sh::fw::web
