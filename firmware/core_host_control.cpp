// The core's controls for the commissioning web page: the effects of the CAN commands (trigger,
// free-run rate, time budget, model selection, clear fault) and of the heartbeat time 0x1017,
// taken from another thread. Nothing is acknowledged on the bus, since no command frame came;
// the dictionary is updated so a manager reads the values the page set.
#include "firmware/firmware_core.hpp"

namespace sh::fw {

using protocol::NmtState;

Status FirmwareCore::RequestTrigger() {
  const FirmwareState s = state_.load();
  if (s != FirmwareState::kReady && s != FirmwareState::kBusy) {
    return Status::Error(StatusCode::kFailedPrecondition, "trigger refused in state %s",
                         s == FirmwareState::kFault ? "fault" : "init");
  }
  // Results go out only when operational, so a trigger would give nothing to see.
  if (nmt_.load() != NmtState::kOperational) {
    return Status::Error(StatusCode::kFailedPrecondition,
                         "trigger refused: the node is not operational (NMT)");
  }
  if (!QueueTrigger(0, MonotonicNs())) {
    return Status::Error(StatusCode::kResourceExhausted, "trigger queue full");
  }
  return Status::Ok();
}

void FirmwareCore::SetFreeRunRate(uint16_t rate_dhz) {
  free_run_dhz_ = rate_dhz;
  canopen_.SetSettings(CurrentSettings());
  cv_.notify_all();  // the worker recomputes its next tick
}

void FirmwareCore::SetTimeBudget(uint16_t budget_ms) {
  budget_ms_ = budget_ms;
  canopen_.SetSettings(CurrentSettings());
}

Status FirmwareCore::SelectModels(uint32_t model_mask) {
  SH_RETURN_IF_ERROR(protocol::CheckModelMask(model_mask, model_count_));
  model_mask_ = model_mask;
  canopen_.SetSettings(CurrentSettings());
  return Status::Ok();
}

void FirmwareCore::SetHeartbeat(uint16_t heartbeat_ms) {
  heartbeat_ms_ = heartbeat_ms;
  canopen_.SetSettings(CurrentSettings());
  heartbeat_changed_ = true;  // the heartbeat thread takes the new period at once
}

void FirmwareCore::RequestClearFault() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    clear_requested_ = true;
    clear_ack_ = false;
  }
  cv_.notify_all();
}

void FirmwareCore::RecordNext(int pairs) {
  if (pairs > 0) record_pending_ += pairs;
}

bool FirmwareCore::TakeRecordRequest() {
  int pending = record_pending_.load();
  while (pending > 0) {
    if (record_pending_.compare_exchange_weak(pending, pending - 1)) return true;
  }
  return false;
}

}  // namespace sh::fw
