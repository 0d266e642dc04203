// The CAN side of the core: the can_rx thread's dispatch of NMT, commands and the CANopen
// services, and every frame the core sends (results through SendFrame, acknowledgements, EMCY).
#include "firmware/core_support.hpp"
#include "firmware/firmware_core.hpp"
#include "firmware/realtime.hpp"

namespace sh::fw {

using namespace sh::protocol;

void FirmwareCore::CanRxLoop() {
  PrefaultStack();
  while (!stopping_.load()) {
    CanFrame frame;
    const Result<bool> got = dev_.can->Receive(&frame, 100);
    if (!got.ok()) {
      SleepNs(10'000'000);  // interface down or bus-off: the heartbeat thread reports it
      continue;
    }
    if (*got && !frame.error) HandleFrame(frame);
  }
}

void FirmwareCore::HandleFrame(const CanFrame& frame) {
  {
    // SDO, LSS and PDO-mode requests; what they ask of the core comes back in `events`.
    Vector<CanFrame, kCanopenMaxReplies> replies;
    CanopenEvents events;
    if (canopen_.HandleFrame(frame, nmt_.load(), MonotonicNs(), replies, &events)) {
      // Settings take effect before the SDO confirmation leaves; what a command or a new node
      // id sends follows it.
      ApplyCanopenSettings(events);
      for (const CanFrame& f : replies) (void)SendFrame(f);
      HandleCanopenEvents(events);
      return;
    }
  }
  if (frame.id == kCobNmt && !frame.extended) {
    const Result<NmtRequest> nmt = DecodeNmt(frame, node_);
    if (!nmt.ok() || !nmt->addressed) return;
    switch (nmt->command) {
      case NmtCommand::kStart:
        nmt_ = NmtState::kOperational;
        break;
      case NmtCommand::kStop:
        nmt_ = NmtState::kStopped;
        break;
      case NmtCommand::kEnterPreOperational:
        nmt_ = NmtState::kPreOperational;
        break;
      case NmtCommand::kResetNode:
        ResetCommunication(true);
        break;
      case NmtCommand::kResetCommunication:
        ResetCommunication(false);
        break;
    }
    SetOutputs();
    return;
  }
  if (frame.id != kCobCommand + node_ || frame.extended) return;
  if (nmt_.load() != NmtState::kOperational) return;  // as in CANopen: RPDOs only when operational
  if (!canopen_.RpdoValid(canopen::kRpdoCommand)) return;  // switched off by the manager
  canopen_.StoreCommand(frame);
  HandleCommand(frame);
}

void FirmwareCore::ApplyCanopenSettings(const CanopenEvents& events) {
  if (events.heartbeat_changed) {
    heartbeat_ms_ = canopen_.settings().heartbeat_ms;
    heartbeat_changed_ = true;
  }
  if (events.settings_changed) {
    const CanopenSettings s = canopen_.settings();
    budget_ms_ = s.budget_ms;
    model_mask_ = s.model_mask;
    free_run_dhz_ = s.free_run_dhz;
    cv_.notify_all();
  }
}

void FirmwareCore::HandleCanopenEvents(const CanopenEvents& events) {
  if (events.has_command && nmt_.load() == NmtState::kOperational) {
    HandleCommand(events.command);
  }
  if (events.node_id_changed) ResetCommunication(false);
  if (events.rpdo_length_error) {
    SendEmcy(EmcyCode::kPdoLengthError, events.rpdo_detail);
  }
}

CanopenSettings FirmwareCore::CurrentSettings() const {
  CanopenSettings s = canopen_.settings();
  s.heartbeat_ms = static_cast<uint16_t>(heartbeat_ms_.load());
  s.budget_ms = budget_ms_.load();
  s.model_mask = model_mask_.load();
  s.free_run_dhz = free_run_dhz_.load();
  return s;
}

void FirmwareCore::ResetCommunication(bool reset_node) {
  if (reset_node) {
    // Reset node also returns the application's settings to their configured values.
    CanopenSettings power_on = canopen_.settings();
    power_on.heartbeat_ms = static_cast<uint16_t>(config_.heartbeat_ms);
    power_on.budget_ms = config_.budget_ms;
    power_on.free_run_dhz = config_.free_run_dhz;
    power_on.result_mode = config_.result_mode;
    const uint32_t loaded = model_count_ >= 32 ? 0xFFFFFFFFu : (1u << model_count_) - 1;
    power_on.model_mask = (config_.model_mask & loaded) != 0 ? config_.model_mask & loaded : loaded;
    budget_ms_ = power_on.budget_ms;
    free_run_dhz_ = power_on.free_run_dhz;
    model_mask_ = power_on.model_mask;
    node_ = canopen_.ResetNode(power_on);
    cv_.notify_all();
  } else {
    node_ = canopen_.ResetCommunication();
  }
  heartbeat_ms_ = canopen_.settings().heartbeat_ms;
  heartbeat_changed_ = true;
  const Result<CanFrame> boot = EncodeBootUp(node_);
  if (boot.ok()) (void)SendFrame(*boot);
  nmt_ = NmtState::kOperational;  // self-starting
  if (node_.load() == canopen::kNodeIdUnconfigured) {
    CoreLog("%s: node unconfigured (id 0xFF): LSS only until an id is configured",
            reset_node ? "reset node" : "reset communication");
    return;
  }
  CoreLog("%s: node id %u", reset_node ? "reset node" : "reset communication", node_.load());
}

void FirmwareCore::SendIfValid(int tpdo, const CanFrame& frame) {
  if (canopen_.TpdoValid(tpdo)) (void)SendFrame(frame);
}

void FirmwareCore::HandleCommand(const CanFrame& frame) {
  if (frame.len > 0 && frame.data[0] == kCommandIdle) return;
  const Result<Command> cmd = DecodeCommand(frame, node_);
  if (!cmd.ok()) {
    SendAck(frame, cmd.status());
    return;
  }
  switch (cmd->code) {
    case CommandCode::kTrigger: {
      const FirmwareState s = state_.load();
      if (s != FirmwareState::kReady && s != FirmwareState::kBusy) {
        SendAck(frame, Status::Error(StatusCode::kFailedPrecondition, "trigger refused in state %u",
                                     static_cast<unsigned>(s)));
        return;
      }
      if (!QueueTrigger(cmd->request_id, MonotonicNs(), &frame)) {
        SendAck(frame, Status::Error(StatusCode::kFailedPrecondition, "trigger queue full"));
      }
      return;
    }
    case CommandCode::kSelectModels: {
      const Status s = CheckModelMask(cmd->model_mask, model_count_);
      if (s.ok()) model_mask_ = cmd->model_mask;
      canopen_.SetSettings(CurrentSettings());
      SendAck(frame, s);
      return;
    }
    case CommandCode::kSetTimeBudget:
      budget_ms_ = cmd->time_budget_ms;
      canopen_.SetSettings(CurrentSettings());
      SendAck(frame, Status::Ok());
      return;
    case CommandCode::kSetFreeRunRate:
      free_run_dhz_ = cmd->free_run_rate_dhz;
      canopen_.SetSettings(CurrentSettings());
      cv_.notify_all();
      SendAck(frame, Status::Ok());
      return;
    case CommandCode::kClearFault: {
      // The worker does it: it owns the camera and the recognition.
      {
        std::lock_guard<std::mutex> lock(mutex_);
        clear_requested_ = true;
        clear_ack_ = true;
        clear_frame_ = frame;
      }
      cv_.notify_all();
      return;
    }
  }
}

Status FirmwareCore::SendFrame(const CanFrame& frame) {
  // Unconfigured (node id 0xFF, CiA 305): no boot-up, heartbeat, EMCY or PDO; only LSS answers.
  if (node_.load() == canopen::kNodeIdUnconfigured && frame.id != canopen::kLssSlaveCobId) {
    return Status::Error(StatusCode::kFailedPrecondition, "node unconfigured: LSS only");
  }
  std::lock_guard<std::mutex> lock(send_mutex_);
  const Status s = dev_.can->Send(frame);
  NoteSendError(s);
  return s;
}

void FirmwareCore::NoteSendError(const Status& s) {
  if (s.ok()) return;
  ++counters_.send_errors;
  // The EMCYs of these two follow from the heartbeat thread: the bus cannot take them now.
  if (s.code() == StatusCode::kUnavailable) {
    faults_ |= kFaultCanBusOff;
  } else if (s.code() == StatusCode::kResourceExhausted) {
    faults_ |= kFaultCanTxDropped;
  }
}

void FirmwareCore::SendEmcy(EmcyCode code, uint32_t detail) {
  canopen::EmcyMessage error, reset;
  canopen_.Event(static_cast<uint16_t>(code), detail, &error, &reset);
  SendEmcyFrame(error);
  SendEmcyFrame(reset);
}

bool FirmwareCore::SendEmcyFrame(const canopen::EmcyMessage& m) {
  Emcy e;
  e.error_code = m.code;
  e.error_register = m.error_register;
  e.state = state_.load();
  e.detail = m.detail;
  const Result<CanFrame> frame = EncodeEmcy(e, node_);
  const bool sent = frame.ok() && SendFrame(*frame).ok();
  ++counters_.emcy_sent;
  if (dev_.observer != nullptr) dev_.observer->OnEmcy(e);
  return sent;
}

void FirmwareCore::SendAck(const CanFrame& command, const Status& status,
                           std::optional<uint32_t> value) {
  CommandAck ack = MakeCommandAck(command, status);
  if (value) ack.value = *value;
  canopen_.StoreAck(ack);
  const Result<CanFrame> frame = EncodeCommandAck(ack, node_);
  if (frame.ok()) SendIfValid(canopen::kTpdoAck, *frame);
  if (!status.ok()) {
    const Emcy e = MakeCommandRejectedEmcy(command, status, state_.load());
    SendEmcy(static_cast<EmcyCode>(e.error_code), e.detail);
    ++counters_.triggers_rejected;
  }
}

}  // namespace sh::fw
