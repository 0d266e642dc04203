// The worker thread of the core: the trigger queue (CAN, GPIO, the free-run clock), and per
// trigger the strobe, the capture, recognition and the result's publication on CAN, to the
// observer and the recorder.
#include "firmware/core_support.hpp"
#include "firmware/firmware_core.hpp"
#include "firmware/output_frame.hpp"
#include "firmware/realtime.hpp"

namespace sh::fw {

using namespace sh::protocol;

bool FirmwareCore::QueueTrigger(uint16_t request_id, int64_t trigger_ns,
                                const CanFrame* accepted_ack) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (queue_count_ == kTriggerQueueDepth) {
      ++counters_.triggers_dropped;
      return false;
    }
    // Under the queue lock: the worker pops triggers under it, so its result set cannot
    // overtake this ack on the bus (a send is a non-blocking queue write).
    if (accepted_ack != nullptr) SendAck(*accepted_ack, Status::Ok());
    queue_[(queue_head_ + queue_count_) % kTriggerQueueDepth] = {request_id, trigger_ns};
    ++queue_count_;
  }
  ++counters_.triggers_accepted;
  cv_.notify_all();
  return true;
}

void FirmwareCore::WorkerLoop() {
  PrefaultStack();
  int64_t next_free_run_ns = 0;
  uint16_t last_rate = 0;
  while (true) {
    Trigger trigger;
    bool have_trigger = false;
    bool clear = false;
    bool clear_ack = false;
    CanFrame clear_frame;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      const uint16_t rate = free_run_dhz_.load();
      const int64_t now = MonotonicNs();
      if (rate != last_rate) {
        last_rate = rate;
        next_free_run_ns = rate ? now + 10'000'000'000ll / rate : 0;
      }
      // Wake at least every 100 ms so the heartbeat thread can see the loop is alive.
      int64_t wait_ns = 100'000'000;
      if (next_free_run_ns != 0 && next_free_run_ns - now < wait_ns) {
        wait_ns = next_free_run_ns - now;
      }
      if (queue_count_ == 0 && !clear_requested_ && !stop_ && wait_ns > 0) {
        cv_.wait_for(lock, std::chrono::nanoseconds(wait_ns));
      }
      worker_alive_ns_ = MonotonicNs();
      if (stop_) break;
      if (clear_requested_) {
        clear = true;
        clear_requested_ = false;
        clear_ack = clear_ack_;
        clear_frame = clear_frame_;
      } else if (queue_count_ > 0) {
        trigger = queue_[queue_head_];
        queue_head_ = (queue_head_ + 1) % kTriggerQueueDepth;
        --queue_count_;
        have_trigger = true;
      } else if (next_free_run_ns != 0 && MonotonicNs() >= next_free_run_ns) {
        const int64_t period = 10'000'000'000ll / last_rate;
        trigger = {0, next_free_run_ns};
        // A recognition longer than the period skips ticks instead of bursting afterwards.
        next_free_run_ns += period;
        if (next_free_run_ns < MonotonicNs()) next_free_run_ns = MonotonicNs() + period;
        const FirmwareState s = state_.load();
        have_trigger = s == FirmwareState::kReady && nmt_.load() == NmtState::kOperational;
      }
    }
    if (clear) ClearFault(clear_ack ? &clear_frame : nullptr);
    if (have_trigger) RunTrigger(trigger);
    worker_alive_ns_ = MonotonicNs();
  }
}

void FirmwareCore::RunTrigger(const Trigger& trigger) {
  ResultSet& set = result_set_;  // worker thread only; 5 KiB kept off the stack
  set = ResultSet();
  set.request_id = trigger.request_id;

  if (faults_.load() != 0) {
    // Accepted before the fault: answer with an empty set so the PLC is not left waiting.
    set.status =
        (faults_.load() & kFaultCamera) ? ResultStatus::kImageError : ResultStatus::kInternalError;
    PublishResult(&set, nullptr);
    return;
  }
  busy_ = true;
  UpdateState();

  const hal::CameraStats before = dev_.camera->stats();
  hal::StereoFrame frame;
  if (dev_.gpio != nullptr) (void)dev_.gpio->SetOutput(hal::GpioOutput::kStrobe, true);
  const int64_t strobe_on = MonotonicNs();
  Status captured = dev_.camera->Capture(&frame, config_.capture_timeout_ms);
  if (!captured.ok() && FallBackToOneCamera(captured)) {
    captured = dev_.camera->Capture(&frame, config_.capture_timeout_ms);  // from the working side
  }
  if (dev_.gpio != nullptr) {
    SleepNs(int64_t{config_.strobe_min_us} * 1000 - (MonotonicNs() - strobe_on));
    (void)dev_.gpio->SetOutput(hal::GpioOutput::kStrobe, false);
  }
  const hal::CameraStats after = dev_.camera->stats();

  if (!captured.ok()) {
    ++counters_.capture_errors;
    CoreLog("capture: %s", captured.message());
    set.status = ResultStatus::kImageError;
    set.processing_time_us =
        Saturate(static_cast<uint64_t>(MonotonicNs() - trigger.trigger_ns) / 1000, 0xFFFFFFFFu);
    busy_ = false;
    faults_ |= kFaultCamera;
    UpdateState();
    PublishResult(&set, nullptr);
    RaiseFault(kFaultCamera, EmcyCode::kSensor,
               kSensorCaptureFailed | static_cast<uint32_t>(captured.code()) << 16 |
                   Saturate(after.timeouts, 0xFFFF));
    return;
  }
  const uint64_t unpaired = (after.left_unpaired_drops + after.right_unpaired_drops) -
                            (before.left_unpaired_drops + before.right_unpaired_drops);
  if (unpaired > 0) {
    // Frames without a partner were skipped but a pair was found: a warning, not a fault.
    SendEmcy(EmcyCode::kSensor, kSensorUnpairedFrames | Saturate(unpaired, 0xFFFFFF));
  }

  const uint32_t mask = model_mask_.load();
  if (mask != applied_mask_.load()) {
    const Status s = dev_.recognition->SetModelMask(mask);
    if (s.ok()) {
      applied_mask_ = mask;
    } else {
      CoreLog("model mask 0x%x: %s", mask, s.message());
    }
  }
  const hal::CaptureMode mode = capture_mode_.load();
  const float budget_ms = static_cast<float>(budget_ms_.load());
  Status processed;
  if (mode == hal::CaptureMode::kStereo) {
    processed = dev_.recognition->Process(frame, budget_ms, &set);
  } else {
    const bool left = mode == hal::CaptureMode::kLeftOnly;
    processed =
        dev_.recognition->ProcessMonocular(left ? hal::StereoSide::kLeft : hal::StereoSide::kRight,
                                           left ? frame.left : frame.right, budget_ms, &set);
    set.status = ResultStatus::kMonocular;
  }
  if (!processed.ok()) {
    ++counters_.recognition_errors;
    CoreLog("recognition: %s", processed.message());
    set.object_count = 0;
    set.status = ResultStatus::kInternalError;
  }
  if (config_.output_frame != canopen::OutputFrame::kCamera) {
    TransformResultSet(config_.out_T_camera, &set);
  }
  set.processing_time_us =
      Saturate(static_cast<uint64_t>(MonotonicNs() - trigger.trigger_ns) / 1000, 0xFFFFFFFFu);
  busy_ = false;
  UpdateState();
  PublishResult(&set, &frame);
  // A copy for the recorder's writer thread (no heap, never waits); a full ring drops the pair.
  // On one camera, the image of the camera in use alone.
  if (dev_.recorder != nullptr && (config_.record_all || TakeRecordRequest())) {
    (void)dev_.recorder->Submit(frame, set);
  }
  if (!processed.ok()) {
    SendEmcy(EmcyCode::kSoftware, static_cast<uint32_t>(processed.code()) << 16);
  }
  dev_.camera->Release();
}

void FirmwareCore::PublishResult(ResultSet* set, const hal::StereoFrame* frame) {
  if (nmt_.load() != NmtState::kOperational) return;  // results only when operational
  Vector<CanFrame>& frames = result_frames_;          // worker thread only
  set->sequence = sequence_;
  set->output_frame = static_cast<uint8_t>(config_.output_frame);
  frames.clear();
  Status encoded = EncodeResultSet(*set, node_, frames);
  if (!encoded.ok()) {
    // Never a clamped pose: the set goes out empty with status 3 and an EMCY names the problem.
    CoreLog("result set %u: %s", set->sequence, encoded.message());
    set->object_count = 0;
    set->status = ResultStatus::kInternalError;
    frames.clear();
    encoded = EncodeResultSet(*set, node_, frames);
  }
  ++sequence_;
  // The dictionary holds the set before its header is on the bus, so a PDO-mode request that
  // follows the header is answered from this set.
  (void)canopen_.StoreResult(*set, frames[frames.size() - 1].data[3]);
  // Header, then the stream's object and end frames, each if its PDO is valid (result mode).
  const bool send_header = canopen_.TpdoValid(canopen::kTpdoHeader);
  const bool send_objects = canopen_.TpdoValid(canopen::kTpdoStreamObject);
  const bool send_end = canopen_.TpdoValid(canopen::kTpdoStreamEnd);
  {
    std::lock_guard<std::mutex> lock(send_mutex_);  // frames of one set back to back
    for (size_t i = 0; i < frames.size(); ++i) {
      const bool last = i + 1 == frames.size();
      if (!(i == 0 ? send_header : last ? send_end : send_objects)) continue;
      const CanFrame& f = frames[i];
      const Status s = dev_.can->Send(f);
      NoteSendError(s);
      if (s.code() == StatusCode::kUnavailable) break;  // bus-off: the rest cannot go either
    }
  }
  UpdateState();
  ++counters_.result_sets;
  if (!encoded.ok()) {
    SendEmcy(EmcyCode::kSoftware, static_cast<uint32_t>(encoded.code()) << 16);
  }
  if (dev_.observer != nullptr) dev_.observer->OnResult(*set, frame);
}

}  // namespace sh::fw
