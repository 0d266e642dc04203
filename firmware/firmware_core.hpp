// The firmware's state machine, independent of the backends: it is given a CanBus, a Gpio, a
// StereoCamera, a Recognition and a DataSource, so the same code runs on the board, in the
// simulator process and in-process in the fault-injection tests.
//
//   init --(tables + calibration loaded and checked)--> ready <--> busy
//     |                                                  |
//     +------------------- fault <----------------------+   (clear-fault command recovers)
//
// Threads (created in Start(), the only allocation after the objects exist):
//   worker    - waits for triggers (queue from CAN and GPIO, or the free-run clock) and runs
//               strobe + capture + recognition + result publication;
//   can_rx    - NMT, commands, and the CANopen services (SDO, LSS, PDO-mode requests, through
//               CanopenNode): acks at once, queues triggers, applies settings;
//   gpio      - rising edges of the trigger input into the trigger queue;
//   heartbeat - heartbeat at its own period (also in fault; 0x1017 may change or stop it), CAN
//               health (bus-off, overrun), SDO timeouts and the liveness callback (systemd
//               watchdog).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <thread>

#include "firmware/canopen/emcy.hpp"
#include "firmware/canopen/nmt.hpp"
#include "firmware/canopen_node.hpp"
#include "firmware/command_codec.hpp"
#include "firmware/fault_bits.hpp"
#include "firmware/recognition.hpp"
#include "firmware/recorder.hpp"
#include "firmware/result_codec.hpp"
#include "hal/camera.hpp"
#include "hal/can.hpp"
#include "hal/gpio.hpp"
#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/pipeline/model_set.hpp"
#include "tables/feature_db_view.hpp"
#include "tables/table_view.hpp"

namespace sh::fw {

using protocol::FirmwareState;

// Where the data of the boot checks come from; called at boot and when a data fault is cleared.
class DataSource {
 public:
  virtual ~DataSource() = default;
  virtual Result<TableView> LoadTable() = 0;
  virtual Result<StereoCalibration> LoadCalibration() = 0;
  // The feature database of the printed models, or an empty view when none is configured.
  virtual Result<FeatureDbView> LoadFeatures() { return FeatureDbView(); }
  // The colour parts' view database (the model set's SHAPE_VIEWS section), or an empty view.
  virtual Result<ShapeViewsView> LoadShapeViews() { return ShapeViewsView(); }
};

// Reports from the core (simulator stdout, tests). Called from the core's threads; must not
// block for long and must not allocate if the run is to stay allocation-free.
class CoreObserver {
 public:
  virtual ~CoreObserver() = default;
  virtual void OnResult(const protocol::ResultSet& set, const hal::StereoFrame* frame) {}
  virtual void OnEmcy(const protocol::Emcy& emcy) {}
  virtual void OnStateChange(FirmwareState state) {}
  // After the boot checks (or a cleared data fault) loaded the model data and initialised
  // recognition; `models` stays valid until the next load.
  virtual void OnDataLoaded(const ModelSet& models) {}
  virtual void OnAlive() {}  // from the heartbeat thread while the worker loop is responsive
};

struct CoreConfig {
  uint8_t node_id = 1;
  uint32_t heartbeat_ms = 200;  // 0 = no heartbeat (0x1017 may set it later)
  int capture_timeout_ms = 500;
  uint16_t budget_ms = 1000;
  uint16_t free_run_dhz = 0;
  uint32_t model_mask = 0xFFFFFFFFu;  // masked to the loaded models at boot
  int strobe_min_us = 0;              // strobe held at least this long (illumination settle)
  int sched_fifo_priority = 0;        // worker thread; 0 = normal
  canopen::ResultMode result_mode = canopen::ResultMode::kStream;
  // Poses are reported in this frame: out_T_camera maps the left camera into it.
  canopen::OutputFrame output_frame = canopen::OutputFrame::kCamera;
  RigidTransform out_T_camera;
  // Not ok: the boot could not read the cell's geometry (a table_file or handeye file missing or
  // malformed, output_frame = table without a table pose), the message naming the key and the
  // file. Start raises kFaultCellGeometry from it after the boot-up instead of refusing to start:
  // a node absent from the bus cannot tell the PLC what is wrong, and a node in fault reports no
  // pose, so none goes out in a frame other than the configured one. The files are read at boot
  // only, so a clear-fault keeps the fault; a restart once the file is repaired clears it.
  Status cell_geometry = Status::Ok();
  uint32_t serial_number = 0;         // 0x1018 sub 4 and the LSS identity
  const char* hardware_version = "";  // 0x1009
  // Lock the memory mapped at the end of Start (every thread started, recognition initialised,
  // the camera's buffers allocated) and again after a data reload or a camera restart
  // (LockMemory: mlockall(MCL_CURRENT)); refused = logged once, the firmware runs unlocked.
  bool lock_memory = false;
  // With a recorder: every triggered pair is recorded (record_all), or only as many as
  // RecordNext asked for.
  bool record_all = true;
};

struct CoreDevices {
  hal::CanBus* can = nullptr;
  hal::Gpio* gpio = nullptr;  // may be null: no hardware trigger, no outputs
  hal::StereoCamera* camera = nullptr;
  Recognition* recognition = nullptr;
  DataSource* data = nullptr;
  CoreObserver* observer = nullptr;        // may be null
  canopen::LssStore* lss_store = nullptr;  // may be null: LSS store is answered "not supported"
  Recorder* recorder = nullptr;            // may be null: no recording
};

struct CoreCounters {
  uint64_t triggers_accepted = 0;
  uint64_t triggers_rejected = 0;
  uint64_t triggers_dropped = 0;  // queue full
  uint64_t result_sets = 0;
  uint64_t capture_errors = 0;
  uint64_t recognition_errors = 0;
  uint64_t emcy_sent = 0;
  uint64_t heartbeats = 0;
  uint64_t send_errors = 0;
};

// The counters as the core keeps them: each written by several threads, read as a snapshot.
struct AtomicCoreCounters {
  std::atomic<uint64_t> triggers_accepted{0};
  std::atomic<uint64_t> triggers_rejected{0};
  std::atomic<uint64_t> triggers_dropped{0};
  std::atomic<uint64_t> result_sets{0};
  std::atomic<uint64_t> capture_errors{0};
  std::atomic<uint64_t> recognition_errors{0};
  std::atomic<uint64_t> emcy_sent{0};
  std::atomic<uint64_t> heartbeats{0};
  std::atomic<uint64_t> send_errors{0};
  CoreCounters Snapshot() const;
};

inline constexpr size_t kTriggerQueueDepth = 8;

class FirmwareCore final : public RecorderObserver {
 public:
  FirmwareCore() = default;
  ~FirmwareCore() override { Stop(); }
  FirmwareCore(const FirmwareCore&) = delete;
  FirmwareCore& operator=(const FirmwareCore&) = delete;

  // Boot: boot-up message, data load and checks, camera start, recognition init; then the
  // threads. A failing check leaves the core in fault (with its EMCY), not an error: only
  // missing devices or a bad configuration return a non-ok Status.
  Status Start(const CoreConfig& config, const CoreDevices& devices);
  // Stops and joins the threads. Safe to call twice.
  void Stop();

  FirmwareState state() const { return state_.load(); }
  protocol::NmtState nmt_state() const { return nmt_.load(); }
  uint32_t fault_bits() const { return faults_.load(); }
  // The camera results come from while one has failed (monocular fallback), or kStereo.
  hal::CaptureMode capture_mode() const { return capture_mode_.load(); }
  CoreCounters counters() const;
  uint16_t budget_ms() const { return budget_ms_.load(); }
  uint16_t free_run_dhz() const { return free_run_dhz_.load(); }
  uint32_t model_mask() const { return model_mask_.load(); }
  size_t loaded_models() const { return model_count_; }
  uint16_t next_sequence() const { return sequence_; }
  uint8_t node_id() const { return node_.load(); }
  uint32_t heartbeat_ms() const { return heartbeat_ms_.load(); }
  const CanopenNode& canopen() const { return canopen_; }

  // The recorder's writer could not write a pair (errno) / writes again: a warning (EMCY 0xFF10,
  // error register bit 7), not a fault.
  void OnRecordFailed(int error_number) override;
  void OnRecordRecovered() override;

  // Same path as a CAN trigger with request id 0 / a GPIO edge (tests, demo). With `accepted_ack`
  // the OK ack of that command is sent before the worker can see the trigger, so a PLC always
  // receives the ack of a trigger before its result set.
  bool QueueTrigger(uint16_t request_id, int64_t trigger_ns,
                    const hal::CanFrame* accepted_ack = nullptr);

  // The commissioning page's controls (core_host_control.cpp): the same effects as the CAN
  // commands, without an ack on the bus. Any thread; none of them waits for the worker.
  // A trigger with request id 0; refused when not ready or busy, or not operational.
  Status RequestTrigger();
  void SetFreeRunRate(uint16_t rate_dhz);
  void SetTimeBudget(uint16_t budget_ms);
  Status SelectModels(uint32_t model_mask);  // CheckModelMask against the loaded models
  void SetHeartbeat(uint16_t heartbeat_ms);  // 0 = off
  void RequestClearFault();
  // The next `pairs` triggered pairs are recorded (record_all = false); adds to what is pending.
  void RecordNext(int pairs);
  int record_pending() const { return record_pending_.load(); }
  bool recording() const { return dev_.recorder != nullptr; }

 private:
  struct Trigger {
    uint16_t request_id = 0;
    int64_t trigger_ns = 0;  // CLOCK_MONOTONIC
  };

  void WorkerLoop();
  void CanRxLoop();
  void GpioLoop();
  void HeartbeatLoop();

  void LoadData();  // boot checks; sets data faults
  // config_.cell_geometry's fault: logged with its message, EMCY 0x6300 kDetailCellGeometry.
  void RaiseCellGeometryFault();
  void RunTrigger(const Trigger& trigger);
  bool TakeRecordRequest();  // one of the pairs RecordNext asked for, if any is pending
  void PublishResult(protocol::ResultSet* set, const hal::StereoFrame* frame);
  void HandleFrame(const hal::CanFrame& frame);
  void HandleCommand(const hal::CanFrame& frame);
  // `frame`: the clear-fault command to acknowledge, or nullptr (the web page's request).
  void ClearFault(const hal::CanFrame* frame);
  // After a failed stereo capture: when one camera alone is silent and recognition can work
  // from one image, restarts the camera on the other side alone, raises the one-camera warning
  // (EMCY 0x7300) and returns true.
  bool FallBackToOneCamera(const Status& failure);
  // After the camera failed to start in stereo (a camera not found, at boot or at clear-fault):
  // when recognition can work from one image, starts the left camera alone, else the right one,
  // raises the one-camera warning naming the other side and returns true.
  bool StartOnOneCamera(const Status& failure);
  // Restarts the camera in `mode`; false (logged) when it does not start. The caller locks the
  // new buffers (LockCurrentMemory) once it has restarted what it needs.
  bool RestartCamera(hal::CaptureMode mode);
  // With config_.lock_memory: LockMemory(), the first refusal logged.
  void LockCurrentMemory();
  // Clear-fault while on one camera: back to stereo when a stereo pair arrives, else back to the
  // one camera. True when stereo again.
  bool TryStereoAgain();

  // A fault or warning condition becomes active: its EMCY with the error register.
  void RaiseFault(uint32_t bit, protocol::EmcyCode code, uint32_t detail);
  // Conditions that ended: the error reset EMCY (0x0000) with the register that remains.
  void ClearConditions(uint32_t bits);
  // An error without lasting cause: its EMCY followed by the error reset.
  void SendEmcy(protocol::EmcyCode code, uint32_t detail);
  // True when the bus took the frame.
  bool SendEmcyFrame(const canopen::EmcyMessage& m);
  void ApplyCanopenSettings(const CanopenEvents& events);
  void HandleCanopenEvents(const CanopenEvents& events);
  void ResetCommunication(bool reset_node);
  CanopenSettings CurrentSettings() const;
  void SendIfValid(int tpdo, const hal::CanFrame& frame);
  // The ack of a command; `value` replaces the value field the ack would echo.
  void SendAck(const hal::CanFrame& command, const Status& status,
               std::optional<uint32_t> value = std::nullopt);
  Status SendFrame(const hal::CanFrame& frame);
  void NoteSendError(const Status& send_status);  // counts it; bus-off and full queue are faults
  void UpdateState();
  void SetState(FirmwareState state);
  void SetOutputs();

  CoreConfig config_;
  CoreDevices dev_;
  std::atomic<uint8_t> node_{1};  // changes with LSS + reset communication
  std::atomic<uint32_t> heartbeat_ms_{200};
  std::atomic<bool> heartbeat_changed_{false};
  CanopenNode canopen_;

  std::atomic<FirmwareState> state_{FirmwareState::kInit};
  std::atomic<protocol::NmtState> nmt_{protocol::NmtState::kPreOperational};
  std::atomic<uint32_t> faults_{0};
  std::atomic<bool> busy_{false};
  std::atomic<bool> booted_{false};
  std::atomic<uint16_t> budget_ms_{1000};
  std::atomic<uint16_t> free_run_dhz_{0};
  std::atomic<uint32_t> model_mask_{0};
  std::atomic<uint32_t> applied_mask_{0};  // worker-side copy given to the recognition
  std::atomic<bool> camera_started_{false};
  std::atomic<hal::CaptureMode> capture_mode_{hal::CaptureMode::kStereo};
  size_t model_count_ = 0;
  // The model data of the last load (worker thread): recognition and observers see them through
  // models_ until the next load.
  TableView table_;
  FeatureDbView features_;
  ShapeViewsView shape_views_;
  ModelSet models_;

  // Trigger queue and clear-fault request, guarded by mutex_.
  std::mutex mutex_;
  std::condition_variable cv_;
  Trigger queue_[kTriggerQueueDepth];
  size_t queue_head_ = 0, queue_count_ = 0;
  bool clear_requested_ = false;
  bool clear_ack_ = false;  // the clear request came over CAN: clear_frame_ is acknowledged
  hal::CanFrame clear_frame_;
  bool stop_ = false;

  std::atomic<int> record_pending_{0};  // pairs still to record when not record_all
  std::atomic<bool> stopping_{false};
  std::atomic<int64_t> worker_alive_ns_{0};
  std::mutex send_mutex_;  // one writer at a time keeps a result set's frames together
  AtomicCoreCounters counters_;
  uint16_t sequence_ = 0;                                            // worker only
  protocol::ResultSet result_set_;                                   // worker only
  Vector<hal::CanFrame, protocol::kMaxResultFrames> result_frames_;  // worker only

  std::thread worker_, can_rx_, gpio_, heartbeat_;
  bool threads_started_ = false;
  // Start (the calling thread) and the worker (camera restarts, clear-fault) both lock memory.
  std::atomic<bool> lock_refusal_logged_{false};
};

// CLOCK_MONOTONIC in nanoseconds (the time base of triggers and the pipeline's budget).
int64_t MonotonicNs();

}  // namespace sh::fw
