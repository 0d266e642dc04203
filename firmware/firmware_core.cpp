// The core's life: start (threads, boot-up, boot checks), stop, counters, and the boot checks
// that load the model data and initialise recognition (again after a cleared data fault). The
// threads' work is in core_trigger_worker, core_camera_supervisor, core_can_dispatcher and
// core_heartbeat_faults.
#include "firmware/firmware_core.hpp"

#include "firmware/core_support.hpp"
#include "firmware/realtime.hpp"

namespace sh::fw {

using namespace sh::protocol;

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
    CoreLog("camera start failed: %s", camera.message());
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
    if (!fifo.ok()) CoreLog("%s; running with normal scheduling", fifo.message());
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
    CoreLog("model tables: %s", table.status().message());
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
    CoreLog("feature database: %s", features.status().message());
    RaiseFault(kFaultTables, EmcyCode::kDataSet, kDetailFeatures);
  }
  // The colour parts' view database (the model set's SHAPE_VIEWS section): model data too.
  const Result<ShapeViewsView> views = dev_.data->LoadShapeViews();
  if (!views.ok()) {
    CoreLog("view database: %s", views.status().message());
    RaiseFault(kFaultTables, EmcyCode::kDataSet, kDetailTables);
  }
  const Result<StereoCalibration> calib = dev_.data->LoadCalibration();
  if (!calib.ok()) {
    CoreLog("calibration: %s", calib.status().message());
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
    CoreLog("model data: %zu models (1..%u model ids)", model_count_,
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
    CoreLog("recognition init: %s", init.message());
    RaiseFault(kFaultRecognition, EmcyCode::kSoftware, kDetailRecognitionInit);
    return;
  }
  model_mask_ = mask;
  applied_mask_ = mask;
  canopen_.SetSettings(CurrentSettings());
  CoreLog("loaded %zu models, model mask 0x%x", model_count_, mask);
  if (dev_.observer != nullptr) dev_.observer->OnDataLoaded(models_);
}

void FirmwareCore::RaiseCellGeometryFault() {
  CoreLog("cell geometry: %s; read at boot only: restart once it is repaired",
          config_.cell_geometry.message());
  RaiseFault(kFaultCellGeometry, EmcyCode::kDataSet, kDetailCellGeometry);
}

}  // namespace sh::fw
