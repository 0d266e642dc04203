#include "firmware/firmware_core.hpp"

#include <time.h>

#include <chrono>
#include <cstdarg>
#include <cstdio>

#include "firmware/can_health.hpp"
#include "firmware/output_frame.hpp"
#include "firmware/realtime.hpp"

namespace sh::fw {

using namespace sh::protocol;

int64_t MonotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

namespace {

void Log(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
void Log(const char* fmt, ...) {
  // stderr is unbuffered: no allocation, one write per message (journald adds the time).
  char line[320];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(line, sizeof(line), fmt, args);
  va_end(args);
  std::fprintf(stderr, "stereohash-fw: %s\n", line);
}

void SleepNs(int64_t ns) {
  if (ns <= 0) return;
  timespec ts{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
  nanosleep(&ts, nullptr);
}

uint32_t Saturate(uint64_t v, uint32_t max) { return v > max ? max : static_cast<uint32_t>(v); }

}  // namespace

Status FirmwareCore::Start(const CoreConfig& config, const CoreDevices& devices) {
  if (threads_started_) {
    return Status::Error(StatusCode::kFailedPrecondition, "firmware core already started");
  }
  if (devices.can == nullptr || devices.camera == nullptr || devices.recognition == nullptr ||
      devices.data == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "firmware core needs a CAN bus, a camera, a recognition and data");
  }
  // 0xFF (stored by LSS): the node starts unconfigured and waits for an id from LSS.
  if (config.node_id != canopen::kNodeIdUnconfigured)
    SH_RETURN_IF_ERROR(CheckNodeId(config.node_id));
  if ((config.heartbeat_ms != 0 && config.heartbeat_ms < 10) || config.heartbeat_ms > 10000 ||
      config.capture_timeout_ms <= 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "heartbeat period %u ms or capture timeout %d ms out of range",
                         config.heartbeat_ms, config.capture_timeout_ms);
  }
  config_ = config;
  dev_ = devices;
  node_ = config.node_id;
  heartbeat_ms_ = config.heartbeat_ms;
  budget_ms_ = config.budget_ms;
  free_run_dhz_ = config.free_run_dhz;
  model_mask_ = config.model_mask;
  CanopenDeviceInfo info;
  info.node_id = config.node_id;
  info.serial_number = config.serial_number;
  info.hardware_version = config.hardware_version;
  info.output_frame = config.output_frame;
  info.lss_store = devices.lss_store;
  CanopenSettings settings = CurrentSettings();
  settings.result_mode = config.result_mode;
  canopen_.Init(info, settings);
  stop_ = false;
  stopping_ = false;
  queue_count_ = 0;
  clear_requested_ = false;
  faults_ = 0;

  // Boot-up first (CiA 301): the PLC learns the node exists before any EMCY of the checks.
  const Result<CanFrame> boot = EncodeBootUp(node_);
  if (boot.ok()) (void)SendFrame(*boot);
  nmt_ = NmtState::kOperational;  // self-starting node

  if (!config_.cell_geometry.ok()) RaiseCellGeometryFault();
  LoadData();
  canopen_.SetSettings(CurrentSettings());
  const Status camera = dev_.camera->Start();
  if (camera.ok()) {
    camera_started_ = true;
  } else if (!StartOnOneCamera(camera)) {
    Log("camera start failed: %s", camera.message());
    RaiseFault(kFaultCamera, EmcyCode::kSensor,
               kSensorStartFailed | static_cast<uint32_t>(camera.code()) << 16);
  }
  booted_ = true;
  UpdateState();

  worker_alive_ns_ = MonotonicNs();
  worker_ = std::thread([this] { WorkerLoop(); });
  can_rx_ = std::thread([this] { CanRxLoop(); });
  gpio_ = std::thread([this] { GpioLoop(); });
  heartbeat_ = std::thread([this] { HeartbeatLoop(); });
  threads_started_ = true;
  // Every buffer of the per-frame path exists now: locking them is what keeps page faults out of
  // it (docs/memory.md, "Locked memory").
  LockCurrentMemory();
  if (config_.sched_fifo_priority > 0) {
    const Status fifo = SetFifoPriority(worker_, config_.sched_fifo_priority);
    if (!fifo.ok()) Log("%s; running with normal scheduling", fifo.message());
  }
  return Status::Ok();
}

void FirmwareCore::Stop() {
  if (!threads_started_) return;
  stopping_ = true;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  worker_.join();
  can_rx_.join();
  gpio_.join();
  heartbeat_.join();
  threads_started_ = false;
  if (camera_started_) {
    (void)dev_.camera->Stop();
    camera_started_ = false;
  }
}

CoreCounters FirmwareCore::counters() const { return counters_.Snapshot(); }

CoreCounters AtomicCoreCounters::Snapshot() const {
  CoreCounters c;
  c.triggers_accepted = triggers_accepted.load();
  c.triggers_rejected = triggers_rejected.load();
  c.triggers_dropped = triggers_dropped.load();
  c.result_sets = result_sets.load();
  c.capture_errors = capture_errors.load();
  c.recognition_errors = recognition_errors.load();
  c.emcy_sent = emcy_sent.load();
  c.heartbeats = heartbeats.load();
  c.send_errors = send_errors.load();
  return c;
}

// ---------------------------------------------------------------------------------------------
// Boot checks

void FirmwareCore::LoadData() {
  faults_ &= ~(kFaultTables | kFaultCalibration | kFaultRecognition);
  const Result<TableView> table = dev_.data->LoadTable();
  if (!table.ok()) {
    Log("model tables: %s", table.status().message());
    RaiseFault(kFaultTables, EmcyCode::kDataSet, kDetailTables);
  }
  // The printed models' feature database: a fault of the model data like the tables.
  Result<FeatureDbView> features = dev_.data->LoadFeatures();
  if (features.ok() && table.ok() &&
      table->model_count() + (features->empty() ? 0 : features->model_count()) >
          canopen::kMaxModelNames) {
    features = Status::Error(
        StatusCode::kOutOfRange, "%u table models and %u printed models exceed the %u model ids",
        table->model_count(), features->model_count(), unsigned{canopen::kMaxModelNames});
  }
  if (!features.ok()) {
    Log("feature database: %s", features.status().message());
    RaiseFault(kFaultTables, EmcyCode::kDataSet, kDetailFeatures);
  }
  // The colour parts' view database (the model set's SHAPE_VIEWS section): model data too.
  const Result<ShapeViewsView> views = dev_.data->LoadShapeViews();
  if (!views.ok()) {
    Log("view database: %s", views.status().message());
    RaiseFault(kFaultTables, EmcyCode::kDataSet, kDetailTables);
  }
  const Result<StereoCalibration> calib = dev_.data->LoadCalibration();
  if (!calib.ok()) {
    Log("calibration: %s", calib.status().message());
    RaiseFault(kFaultCalibration, EmcyCode::kDataSet, kDetailCalibration);
  }
  if (!table.ok() || !features.ok() || !views.ok() || !calib.ok()) return;

  // Model ids: the hash tables' polyhedra, the colour parts, then the printed models (ModelSet's
  // order).
  table_ = *table;
  features_ = *features;
  shape_views_ = *views;
  models_ = ModelSet(&table_, &shape_views_, &features_);
  model_count_ = models_.count();
  if (model_count_ == 0 || model_count_ > canopen::kMaxModelNames) {
    Log("model data: %zu models (1..%u model ids)", model_count_,
        unsigned{canopen::kMaxModelNames});
    RaiseFault(kFaultTables, EmcyCode::kDataSet,
               model_count_ == 0 ? kDetailTables : kDetailFeatures);
    return;
  }
  // Colour parts need colour frames: the camera asks for a colour format from its next start
  // (boot starts it after this; a set reloaded by clear-fault takes effect at the next restart).
  dev_.camera->SetColourWanted(models_.shape_count() > 0);
  const char* names[canopen::kMaxModelNames] = {};
  for (size_t m = 0; m < model_count_ && m < canopen::kMaxModelNames; ++m) {
    names[m] = models_.model(static_cast<uint32_t>(m)).name;
  }
  canopen_.SetModels(
      names, model_count_ < canopen::kMaxModelNames ? model_count_ : canopen::kMaxModelNames);
  const uint32_t loaded = model_count_ >= 32 ? 0xFFFFFFFFu : (1u << model_count_) - 1;
  uint32_t mask = config_.model_mask & loaded;
  if (mask == 0) mask = loaded;
  const Status init = dev_.recognition->Init(*calib, models_, mask);
  if (!init.ok()) {
    Log("recognition init: %s", init.message());
    RaiseFault(kFaultRecognition, EmcyCode::kSoftware, kDetailRecognitionInit);
    return;
  }
  model_mask_ = mask;
  applied_mask_ = mask;
  canopen_.SetSettings(CurrentSettings());
  Log("loaded %zu models, model mask 0x%x", model_count_, mask);
  if (dev_.observer != nullptr) dev_.observer->OnDataLoaded(models_);
}

void FirmwareCore::RaiseCellGeometryFault() {
  Log("cell geometry: %s; read at boot only: restart once it is repaired",
      config_.cell_geometry.message());
  RaiseFault(kFaultCellGeometry, EmcyCode::kDataSet, kDetailCellGeometry);
}

// ---------------------------------------------------------------------------------------------
// State

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
  Log("recording: a pair could not be written (errno %d); recording continues", error_number);
  SendEmcyFrame(canopen_.Raise(kWarningRecording, static_cast<uint16_t>(EmcyCode::kRecording),
                               static_cast<uint32_t>(error_number)));
}

void FirmwareCore::OnRecordRecovered() {
  Log("recording: pairs are written again");
  ClearConditions(kWarningRecording);
}

void FirmwareCore::ClearConditions(uint32_t bits) {
  canopen::EmcyMessage reset;
  if (bits != 0 && canopen_.ClearConditions(bits, &reset)) SendEmcyFrame(reset);
}

// ---------------------------------------------------------------------------------------------
// CAN output

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

// ---------------------------------------------------------------------------------------------
// Triggers

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
    Log("capture: %s", captured.message());
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
      Log("model mask 0x%x: %s", mask, s.message());
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
    Log("recognition: %s", processed.message());
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
    Log("result set %u: %s", set->sequence, encoded.message());
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

bool FirmwareCore::RestartCamera(hal::CaptureMode mode) {
  if (camera_started_) (void)dev_.camera->Stop();
  camera_started_ = false;
  Status s = dev_.camera->SetCaptureMode(mode);
  if (s.ok()) s = dev_.camera->Start();
  if (!s.ok()) {
    Log("camera restart (%s): %s", hal::CaptureModeName(mode), s.message());
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
  if (!s.ok() && !lock_refusal_logged_.exchange(true)) Log("%s; continuing unlocked", s.message());
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
  Log("%s; continuing with the %s camera alone (monocular results)", failure.message(),
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
    Log("camera start failed: %s; continuing with the %s camera alone (monocular results)",
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
    Log("stereo again: %s", s.message());
  }
  (void)RestartCamera(one);
  return false;
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
      Log("both cameras deliver again: stereo results");
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
      Log("camera restart failed: %s", s.message());
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
    Log("fault cleared");
  } else {
    ack(Status::Error(StatusCode::kFailedPrecondition, "fault persists (causes 0x%x%s)",
                      faults_.load(), still_one_camera ? ", one camera silent" : ""));
  }
  // Error reset (EMCY 0x0000) with the register of what remains: 0 when all cleared.
  ClearConditions(cleared);
}

// ---------------------------------------------------------------------------------------------
// CAN input

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
    Log("%s: node unconfigured (id 0xFF): LSS only until an id is configured",
        reset_node ? "reset node" : "reset communication");
    return;
  }
  Log("%s: node id %u", reset_node ? "reset node" : "reset communication", node_.load());
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

// ---------------------------------------------------------------------------------------------
// GPIO and heartbeat

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
