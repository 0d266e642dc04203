#include "firmware/canopen_node.hpp"

#include "firmware/le_bytes.hpp"

namespace sh::fw {

using namespace sh::canopen;

CanopenNode::CanopenNode() { od_.set_write_handler(this); }

void CanopenNode::Init(const CanopenDeviceInfo& info, const CanopenSettings& settings) {
  std::lock_guard<std::mutex> lock(mutex_);
  output_frame_ = info.output_frame;
  node_id_ = info.node_id;
  od_.ResetCommunication(node_id_);
  od_.Set(kIdxIdentity, 4, info.serial_number);
  od_.SetString(kIdxHardwareVersion, 0, info.hardware_version);
  od_.Set(kIdxSettings, kSubOutputFrame, static_cast<uint8_t>(info.output_frame));
  power_on_heartbeat_ms_ = settings.heartbeat_ms;
  od_.Set(kIdxHeartbeatTime, 0, settings.heartbeat_ms);
  WriteSettingsLocked(settings);
  sdo_.Reset();
  LssIdentity id;
  id.vendor_id = od_.Get(kIdxIdentity, 1);
  id.product_code = od_.Get(kIdxIdentity, 2);
  id.revision = od_.Get(kIdxIdentity, 3);
  id.serial = info.serial_number;
  lss_.Init(id, node_id_, info.lss_store);
}

void CanopenNode::WriteSettingsLocked(const CanopenSettings& s) {
  od_.Set(kIdxSettings, kSubBudget, s.budget_ms);
  od_.Set(kIdxSettings, kSubModelMask, s.model_mask);
  od_.Set(kIdxSettings, kSubFreeRunRate, s.free_run_dhz);
  od_.Set(kIdxSettings, kSubResultMode, static_cast<uint8_t>(s.result_mode));
  ApplyResultMode(&od_, s.result_mode);
}

void CanopenNode::SetSettings(const CanopenSettings& s) {
  std::lock_guard<std::mutex> lock(mutex_);
  WriteSettingsLocked(s);
}

CanopenSettings CanopenNode::settings() const {
  std::lock_guard<std::mutex> lock(mutex_);
  CanopenSettings s;
  s.heartbeat_ms = static_cast<uint16_t>(od_.Get(kIdxHeartbeatTime, 0));
  s.budget_ms = static_cast<uint16_t>(od_.Get(kIdxSettings, kSubBudget));
  s.model_mask = od_.Get(kIdxSettings, kSubModelMask);
  s.free_run_dhz = static_cast<uint16_t>(od_.Get(kIdxSettings, kSubFreeRunRate));
  s.result_mode = static_cast<ResultMode>(od_.Get(kIdxSettings, kSubResultMode));
  return s;
}

uint8_t CanopenNode::node_id() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return node_id_;
}

uint8_t CanopenNode::ResetCommunication() {
  std::lock_guard<std::mutex> lock(mutex_);
  const uint8_t pending = lss_.pending_node_id();
  // 0xFF makes the node unconfigured (CiA 305): LSS only, so that fastscan can find it.
  if ((pending >= protocol::kNodeIdMin && pending <= protocol::kNodeIdMax) ||
      pending == kNodeIdUnconfigured) {
    node_id_ = pending;
  }
  lss_.set_active_node_id(node_id_);
  if (node_id_ == kNodeIdUnconfigured) {
    sdo_.Reset();
    return node_id_;
  }
  // Communication parameters return to their power-on values (the heartbeat time of the
  // configuration); the PDO valid bits follow the result mode, an application setting that a
  // reset communication keeps.
  od_.ResetCommunication(node_id_);
  od_.Set(kIdxHeartbeatTime, 0, power_on_heartbeat_ms_);
  ApplyResultMode(&od_, static_cast<ResultMode>(od_.Get(kIdxSettings, kSubResultMode)));
  sdo_.Reset();
  return node_id_;
}

uint8_t CanopenNode::ResetNode(const CanopenSettings& power_on) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    power_on_heartbeat_ms_ = power_on.heartbeat_ms;
    WriteSettingsLocked(power_on);
  }
  return ResetCommunication();
}

bool CanopenNode::HandleFrame(const hal::CanFrame& frame, protocol::NmtState nmt, int64_t now_ns,
                              Vector<hal::CanFrame>& out, CanopenEvents* events) {
  if (frame.extended || frame.rtr || frame.error) return false;
  std::lock_guard<std::mutex> lock(mutex_);
  if (frame.id == kLssMasterCobId) {
    hal::CanFrame reply;
    const LssOutcome o = lss_.Handle(frame, &reply);
    if (o.respond) (void)out.push_back(reply);
    if (o.apply_pending) {
      events->node_id_changed = true;
      events->new_node_id = lss_.pending_node_id();
    }
    return true;
  }
  // An unconfigured node answers nothing but LSS; the frame is taken so the core ignores it too.
  if (node_id_ == kNodeIdUnconfigured) return true;
  if (nmt == protocol::NmtState::kStopped) return false;
  pending_ = events;
  pending_out_ = &out;
  pending_nmt_ = nmt;
  bool handled = false;
  hal::CanFrame reply;
  if (sdo_.Handle(frame, now_ns, &reply)) {
    (void)out.push_back(reply);
    handled = true;
  } else if (frame.id == CanIdOf(od_.Get(kIdxSdoServer, 1))) {
    handled = true;  // an abort from the client: no answer
  } else if (nmt == protocol::NmtState::kOperational && RpdoFor(od_, frame) == kRpdoRequest) {
    const SdoAbort unpacked = UnpackRpdo(&od_, kRpdoRequest, frame);
    if (unpacked == SdoAbort::kLengthTooLow) {
      events->rpdo_length_error = true;
      events->rpdo_detail = static_cast<uint32_t>(frame.len) << 16 | frame.id;
    } else if (unpacked == SdoAbort::kNone) {
      AnswerRequest(static_cast<uint8_t>(od_.Get(kIdxObjectRequest, kSubRequestCounter)),
                    static_cast<uint8_t>(od_.Get(kIdxObjectRequest, kSubRequestIndex)), out);
    }
    handled = true;
  }
  pending_ = nullptr;
  pending_out_ = nullptr;
  return handled;
}

bool CanopenNode::Poll(int64_t now_ns, hal::CanFrame* abort) {
  std::lock_guard<std::mutex> lock(mutex_);
  return sdo_.Poll(now_ns, abort);
}

void CanopenNode::AnswerRequest(uint8_t counter, uint8_t index, Vector<hal::CanFrame>& out) {
  (void)results_.Answer(counter, index);
  // TPDO5 first, TPDO8 (with the counter again) last: a PLC that sees both counters equal has
  // the whole answer.
  for (int k = 0; k < kTpdoAnswerCount; ++k) {
    const int n = kTpdoAnswerFirst + k;
    if (!CobIdValid(TpdoCobId(od_, n))) continue;
    hal::CanFrame f;
    if (PackTpdo(od_, n, &f).ok()) (void)out.push_back(f);
  }
}

SdoAbort CanopenNode::OnWrite(const OdEntry& e, uint32_t value) {
  if (IsPdoCobIdEntry(e)) return CheckCobIdWrite(e, value);
  switch (e.index) {
    case kIdxErrorHistory:
      return e.sub == 0 ? errors_.WriteHistoryCount(value) : SdoAbort::kNone;
    case kIdxHeartbeatTime:
      // 0 switches the heartbeat off; below 10 ms it would flood the bus.
      if (value != 0 && value < 10) return SdoAbort::kValueTooLow;
      if (pending_ != nullptr) pending_->heartbeat_changed = true;
      return SdoAbort::kNone;
    case kIdxSettings:
      if (e.sub == kSubModelMask && !protocol::CheckModelMask(value, model_count_).ok()) {
        return SdoAbort::kInvalidValue;
      }
      if (e.sub == kSubResultMode) ApplyResultMode(&od_, static_cast<ResultMode>(value));
      if (pending_ != nullptr) pending_->settings_changed = true;
      return SdoAbort::kNone;
    case kIdxObjectRequest:
      if (e.sub == kSubRequestCounter && pending_out_ != nullptr) {
        AnswerRequest(static_cast<uint8_t>(value),
                      static_cast<uint8_t>(od_.Get(kIdxObjectRequest, kSubRequestIndex)),
                      *pending_out_);
      }
      return SdoAbort::kNone;
    case kIdxCommand:
      // As by RPDO1, a command runs only when operational: a confirmed write that then does
      // nothing would leave the client believing it ran. The idle code 0 runs nothing anywhere.
      if (e.sub == kSubCommandCode && value != protocol::kCommandIdle &&
          pending_nmt_ != protocol::NmtState::kOperational) {
        return SdoAbort::kDeviceState;
      }
      if (e.sub == kSubCommandCode && pending_ != nullptr) {
        hal::CanFrame& c = pending_->command;
        c = hal::CanFrame();
        c.id = CanIdOf(od_.Get(kIdxRpdoComm + kRpdoCommand, 1));
        c.len = 8;
        c.data[0] = static_cast<uint8_t>(value);
        protocol::PutU32(&c.data[1], od_.Get(kIdxCommand, kSubCommandArgument));
        pending_->has_command = true;
      }
      return SdoAbort::kNone;
    default:
      return SdoAbort::kNone;
  }
}

EmcyMessage CanopenNode::Raise(uint32_t bit, uint16_t code, uint32_t detail) {
  std::lock_guard<std::mutex> lock(mutex_);
  return errors_.Raise(bit, code, detail);
}

bool CanopenNode::ClearConditions(uint32_t bits, EmcyMessage* reset) {
  std::lock_guard<std::mutex> lock(mutex_);
  return errors_.ClearAll(bits, reset);
}

void CanopenNode::Event(uint16_t code, uint32_t detail, EmcyMessage* error, EmcyMessage* reset) {
  std::lock_guard<std::mutex> lock(mutex_);
  errors_.Event(code, detail, error, reset);
}

uint8_t CanopenNode::error_register() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return errors_.error_register();
}

Status CanopenNode::StoreResult(const protocol::ResultSet& set, uint8_t crc) {
  std::lock_guard<std::mutex> lock(mutex_);
  return results_.Store(set, crc);
}

void CanopenNode::StoreAck(const protocol::CommandAck& ack) {
  std::lock_guard<std::mutex> lock(mutex_);
  StoreCommandAck(&od_, ack);
}

void CanopenNode::StoreCommand(const hal::CanFrame& command) {
  std::lock_guard<std::mutex> lock(mutex_);
  uint8_t data[5] = {};
  for (uint8_t i = 0; i < 5 && i < command.len; ++i) data[i] = command.data[i];
  od_.Set(kIdxCommand, kSubCommandCode, data[0]);
  od_.Set(kIdxCommand, kSubCommandArgument, protocol::GetU32(&data[1]));
}

void CanopenNode::SetDeviceStatus(uint8_t firmware_state, uint32_t fault_causes) {
  std::lock_guard<std::mutex> lock(mutex_);
  od_.Set(kIdxDeviceStatus, kSubFirmwareState, firmware_state);
  od_.Set(kIdxDeviceStatus, kSubFaultCauses, fault_causes);
}

void CanopenNode::SetModels(const char* const* names, size_t count) {
  std::lock_guard<std::mutex> lock(mutex_);
  model_count_ = count;
  od_.Set(kIdxModelCount, 0, count);
  for (uint8_t m = 0; m < kMaxModelNames; ++m) {
    od_.SetString(kIdxModelNames, static_cast<uint8_t>(m + 1), m < count ? names[m] : "");
  }
}

bool CanopenNode::TpdoValid(int n) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return CobIdValid(TpdoCobId(od_, n));
}

uint32_t CanopenNode::TpdoCanId(int n) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return CanIdOf(TpdoCobId(od_, n));
}

bool CanopenNode::RpdoValid(int n) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return CobIdValid(RpdoCobId(od_, n));
}

uint32_t CanopenNode::Get(uint16_t index, uint8_t sub) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return od_.Get(index, sub);
}

}  // namespace sh::fw
