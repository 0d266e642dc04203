// The core's state and faults: the state machine's transitions, the fault and warning bits with
// their EMCY, the clear-fault command, and the threads that keep reporting whatever the state:
// the GPIO trigger input and the heartbeat (CAN health, SDO timeouts, liveness).
#include "firmware/core_support.hpp"
#include "firmware/firmware_core.hpp"
#include "firmware/realtime.hpp"

#include "firmware/can_health.hpp"

namespace sh::fw {

using namespace sh::protocol;

void FirmwareCore::UpdateState() {
  FirmwareState s = FirmwareState::kInit;
  if (faults_.load() != 0) {
    s = FirmwareState::kFault;
  } else if (busy_.load()) {
    s = FirmwareState::kBusy;
  } else if (booted_.load()) {
    s = FirmwareState::kReady;
  }
  SetState(s);
}

void FirmwareCore::SetState(FirmwareState s) {
  const FirmwareState old = state_.exchange(s);
  canopen_.SetDeviceStatus(static_cast<uint8_t>(s), faults_.load());
  if (old == s) return;
  SetOutputs();
  if (dev_.observer != nullptr) dev_.observer->OnStateChange(s);
}

void FirmwareCore::SetOutputs() {
  if (dev_.gpio == nullptr) return;
  const FirmwareState s = state_.load();
  const bool operational = nmt_.load() == NmtState::kOperational;
  (void)dev_.gpio->SetOutput(hal::GpioOutput::kReady, s == FirmwareState::kReady && operational);
  (void)dev_.gpio->SetOutput(hal::GpioOutput::kBusy, s == FirmwareState::kBusy);
}

void FirmwareCore::RaiseFault(uint32_t bit, EmcyCode code, uint32_t detail) {
  faults_ |= bit;
  UpdateState();
  SendEmcyFrame(canopen_.Raise(bit, static_cast<uint16_t>(code), detail));
}

void FirmwareCore::OnRecordFailed(int error_number) {
  CoreLog("recording: a pair could not be written (errno %d); recording continues", error_number);
  SendEmcyFrame(canopen_.Raise(kWarningRecording, static_cast<uint16_t>(EmcyCode::kRecording),
                               static_cast<uint32_t>(error_number)));
}

void FirmwareCore::OnRecordRecovered() {
  CoreLog("recording: pairs are written again");
  ClearConditions(kWarningRecording);
}

void FirmwareCore::ClearConditions(uint32_t bits) {
  canopen::EmcyMessage reset;
  if (bits != 0 && canopen_.ClearConditions(bits, &reset)) SendEmcyFrame(reset);
}

void FirmwareCore::ClearFault(const CanFrame* frame) {
  const auto ack = [&](const Status& status) {
    if (frame != nullptr) SendAck(*frame, status, 0);
  };
  const uint32_t bits = faults_.load();
  const uint32_t before = bits;
  const bool one_camera = capture_mode_.load() != hal::CaptureMode::kStereo;
  if (bits == 0 && !one_camera) {
    ack(Status::Ok());
    return;
  }
  if (bits & (kFaultTables | kFaultCalibration | kFaultRecognition)) LoadData();
  // The table pose and hand-eye files are read at boot only: the fault stays, and its EMCY and
  // log line come again to say why.
  if (bits & kFaultCellGeometry) RaiseCellGeometryFault();
  bool still_one_camera = false;
  if (one_camera) {
    faults_ &= ~kFaultCamera;
    if (TryStereoAgain()) {
      CoreLog("both cameras deliver again: stereo results");
    } else if (camera_started_) {
      still_one_camera = true;
    } else {
      RaiseFault(kFaultCamera, EmcyCode::kSensor, kSensorStartFailed);
    }
  } else if (bits & kFaultCamera) {
    if (camera_started_) (void)dev_.camera->Stop();
    camera_started_ = false;
    faults_ &= ~kFaultCamera;
    const Status s = dev_.camera->Start();
    if (s.ok()) {
      camera_started_ = true;
    } else if (!StartOnOneCamera(s)) {
      CoreLog("camera restart failed: %s", s.message());
      RaiseFault(kFaultCamera, EmcyCode::kSensor,
                 kSensorStartFailed | static_cast<uint32_t>(s.code()) << 16);
    }
  }
  if ((bits & kFaultCanBusOff) && dev_.can->state() != hal::CanBusState::kBusOff) {
    faults_ &= ~kFaultCanBusOff;
  }
  faults_ &= ~kFaultCanTxDropped;
  // A reload may have taken new blocks (another image size, the colour path), a camera start
  // new buffers: locked before the next trigger.
  LockCurrentMemory();
  UpdateState();
  uint32_t cleared = before & ~faults_.load();
  if (one_camera && !still_one_camera) cleared |= kWarningOneCamera;
  if (faults_.load() == 0 && !still_one_camera) {
    ack(Status::Ok());
    CoreLog("fault cleared");
  } else {
    ack(Status::Error(StatusCode::kFailedPrecondition, "fault persists (causes 0x%x%s)",
                      faults_.load(), still_one_camera ? ", one camera silent" : ""));
  }
  // Error reset (EMCY 0x0000) with the register of what remains: 0 when all cleared.
  ClearConditions(cleared);
}

void FirmwareCore::GpioLoop() {
  if (dev_.gpio == nullptr) return;
  PrefaultStack();
  while (!stopping_.load()) {
    hal::GpioEdgeEvent edge;
    const Result<bool> got = dev_.gpio->WaitTriggerRisingEdge(100, &edge);
    if (!got.ok()) {
      if (got.status().code() == StatusCode::kFailedPrecondition) return;  // no trigger line
      SleepNs(100'000'000);
      continue;
    }
    if (!*got) continue;
    const FirmwareState s = state_.load();
    if ((s == FirmwareState::kReady || s == FirmwareState::kBusy) &&
        nmt_.load() == NmtState::kOperational) {
      QueueTrigger(0, static_cast<int64_t>(edge.timestamp_ns));
    } else {
      ++counters_.triggers_rejected;
    }
  }
}

void FirmwareCore::HeartbeatLoop() {
  PrefaultStack();
  // The tick: the heartbeat period, or 100 ms for the health checks when 0x1017 is 0 (off).
  const auto period_of = [](uint32_t ms) { return int64_t{ms != 0 ? ms : 100} * 1'000'000; };
  int64_t period = period_of(heartbeat_ms_.load());
  int64_t next = MonotonicNs() + period;
  // From zero: frames the receive queue lost while the node was still booting (a PLC that
  // started sending early) are reported with the first overrun EMCY, not forgotten.
  CanHealthMonitor health(hal::CanStats{});
  // A health condition's EMCY that the bus refused (its transmit queue still full): sent again
  // each period until it goes out or the condition ends, so that a PLC learns of it. Raising it
  // again would add a second entry to the error history.
  struct UnsentRaise {
    canopen::EmcyMessage emcy;
    uint32_t condition;
  };
  std::optional<UnsentRaise> unsent_raise;
  const int64_t alive_tolerance_ns =
      (int64_t{config_.capture_timeout_ms} + protocol::kTimeBudgetMaxMs + 2000) * 1'000'000ll;
  while (!stopping_.load()) {
    // Sleep in short slices so Stop() is quick, a new heartbeat time applies at once and stale
    // SDO transfers are aborted on time.
    while (!stopping_.load() && MonotonicNs() < next && !heartbeat_changed_.load()) {
      CanFrame abort;
      if (canopen_.Poll(MonotonicNs(), &abort)) (void)SendFrame(abort);
      SleepNs(next - MonotonicNs() < 20'000'000 ? next - MonotonicNs() : 20'000'000);
    }
    if (stopping_.load()) break;
    if (heartbeat_changed_.exchange(false)) {
      period = period_of(heartbeat_ms_.load());
      next = MonotonicNs();
    }
    next += period;
    if (next < MonotonicNs()) next = MonotonicNs() + period;

    if (heartbeat_ms_.load() != 0) {
      const Result<CanFrame> hb = EncodeHeartbeat(node_, nmt_.load());
      if (hb.ok() && SendFrame(*hb).ok()) ++counters_.heartbeats;
    }

    // CAN health: fault bits (also those SendFrame set) and each episode's EMCY once.
    const hal::CanBusState bus = dev_.can->state();
    if (bus == hal::CanBusState::kBusOff) faults_ |= kFaultCanBusOff;
    UpdateState();
    if (unsent_raise && (unsent_raise->condition & (kFaultCanBusOff | kFaultCanTxDropped)) != 0 &&
        (faults_.load() & unsent_raise->condition) == 0)
      unsent_raise.reset();  // a cleared fault: its EMCY is stale
    if (unsent_raise && SendEmcyFrame(unsent_raise->emcy)) unsent_raise.reset();
    const CanHealthMonitor::Actions health_actions =
        health.Step(bus, dev_.can->stats(), faults_.load());
    for (int i = 0; i < health_actions.count; ++i) {
      const CanHealthMonitor::Action& a = health_actions.action[i];
      switch (a.kind) {
        case CanHealthMonitor::Kind::kRaise: {
          const canopen::EmcyMessage m =
              canopen_.Raise(a.condition, static_cast<uint16_t>(a.code), a.detail);
          if (!SendEmcyFrame(m)) unsent_raise = UnsentRaise{m, a.condition};
          break;
        }
        case CanHealthMonitor::Kind::kClear:
          if (unsent_raise && unsent_raise->condition == a.condition) unsent_raise.reset();
          ClearConditions(a.condition);
          break;
        case CanHealthMonitor::Kind::kEvent:
          SendEmcy(a.code, a.detail);
          break;
      }
    }

    if (dev_.observer != nullptr && MonotonicNs() - worker_alive_ns_.load() < alive_tolerance_ns) {
      dev_.observer->OnAlive();
    }
  }
}

}  // namespace sh::fw
