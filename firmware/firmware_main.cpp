// The run of either program on its board: options, configuration, devices, the node id stored by
// LSS, data, the table pose and output frame, recognition, the core, systemd notifications and
// shutdown.
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "firmware/board.hpp"
#include "firmware/config_keys.hpp"
#include "firmware/node_id_file.hpp"
#include "firmware/pipeline_recognition.hpp"
#include "firmware/realtime.hpp"
#include "firmware/recorded_settings.hpp"
#include "firmware/recorder.hpp"
#include "firmware/sd_notify.hpp"
#include "firmware/web/web_service.hpp"
#include "hal/can_log.hpp"
#include "recog/base/crc32.hpp"
#include "recog/base/zeroed.hpp"
#include "recog/camera/handeye_yaml.hpp"
#include "recog/camera/table_yaml.hpp"
#include "tables/input_file.hpp"

namespace sh::fw {
namespace {

volatile sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

void Usage(const Board& board, const FwConfig& defaults) {
  std::printf("usage: %s %s        run with a configuration file\n", board.program(),
              board.NeedsConfigFile() ? "--config FILE" : "[--config FILE]");
  std::printf(
      "options: --run-seconds S (stop after S seconds), --help, --config-keys-markdown (the key "
      "table of docs/firmware.md)\n");
  board.PrintOptions(stdout);
  std::printf("Examples: share/stereohash/*.conf.example; docs/firmware.md.\n\n");
  PrintConfigKeys(stdout, defaults);
}

int Fail(const Board& board, const char* what, const Status& s) {
  std::fprintf(stderr, "%s: %s: %s\n", board.program(), what, s.message());
  return 1;
}

// The systemd watchdog, then the board's own observer and the web page's snapshot.
class MainObserver final : public CoreObserver {
 public:
  MainObserver(SdNotifier* notifier, CoreObserver* board, CoreObserver* web)
      : notifier_(notifier), board_(board), web_(web) {}
  void OnResult(const protocol::ResultSet& set, const hal::StereoFrame* frame) override {
    if (board_ != nullptr) board_->OnResult(set, frame);
    if (web_ != nullptr) web_->OnResult(set, frame);
  }
  void OnEmcy(const protocol::Emcy& emcy) override {
    if (board_ != nullptr) board_->OnEmcy(emcy);
  }
  void OnStateChange(FirmwareState state) override {
    if (board_ != nullptr) board_->OnStateChange(state);
  }
  void OnDataLoaded(const ModelSet& models) override {
    if (board_ != nullptr) board_->OnDataLoaded(models);
    if (web_ != nullptr) web_->OnDataLoaded(models);
  }
  void OnAlive() override {
    (void)notifier_->Notify("WATCHDOG=1");
    if (board_ != nullptr) board_->OnAlive();
  }

 private:
  SdNotifier* notifier_;
  CoreObserver* board_;
  CoreObserver* web_;
};

// A small YAML file (table pose, hand-eye) read and parsed; errors name the file. Boot only.
template <typename T, size_t kBytes>
Result<T> LoadYamlFile(const char* path, Result<T> (*parse)(const char*, size_t)) {
  static char text[kBytes];
  size_t n = 0;
  SH_RETURN_IF_ERROR(ReadInputFile(path, "file", text, sizeof(text), &n));
  Result<T> parsed = parse(text, n);
  if (!parsed.ok()) return parsed.status().WithContext("%s", path);
  return parsed;
}

// A serial number that differs between boards without configuration: CRC-32 of the machine id
// systemd keeps in /etc/machine-id (0 if there is none).
uint32_t MachineSerial() {
  char id[64] = {};
  size_t n = 0;
  if (!ReadInputFile("/etc/machine-id", "machine id", id, sizeof(id) - 1, &n).ok()) return 0;
  while (n > 0 && (id[n - 1] == '\n' || id[n - 1] == ' ')) --n;
  return n > 0 ? Crc32(id, n) : 0;
}

// The options; returns -1 to go on, else the exit code. *config_path: the --config file, or
// nullptr.
int ParseOptions(int argc, char** argv, Board* board, FwConfig* config, long* run_seconds,
                 const char** config_path_out) {
  const char* config_path = nullptr;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--config") && i + 1 < argc) {
      config_path = argv[++i];
    } else if (!std::strcmp(argv[i], "--run-seconds") && i + 1 < argc) {
      char* end = nullptr;
      *run_seconds = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || *run_seconds < 0) {
        std::fprintf(stderr, "%s: --run-seconds: expected seconds, got '%s'\n", board->program(),
                     argv[i]);
        return 2;
      }
    } else if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      Usage(*board, *config);
      return 0;
    } else if (!std::strcmp(argv[i], "--config-keys-markdown")) {
      // docs/firmware.md's table: the board's defaults beside this program's.
      PrintConfigKeysMarkdown(stdout, FwConfig(), *config);
      return 0;
    } else {
      const int taken = board->ParseOption(argc, argv, i);
      if (taken < 0) return 2;  // the board said what is wrong with it
      if (taken == 0) {
        std::fprintf(stderr, "%s: unknown argument '%s' (see --help)\n", board->program(), argv[i]);
        return 2;
      }
      i += taken - 1;
    }
  }
  if (config_path == nullptr && board->NeedsConfigFile()) {
    Usage(*board, *config);
    return 2;
  }
  if (config_path != nullptr) {
    const Status s = LoadConfigFile(config_path, config);
    if (!s.ok()) return Fail(*board, "configuration", s);
  }
  *config_path_out = config_path;
  if (config->backend != board->backend()) {
    return Fail(*board, "configuration",
                Status::Error(StatusCode::kInvalidArgument,
                              "key 'backend': this program runs the %s board; the file is for "
                              "the other program (stereohash-fw: linux, stereohash-fw-sim: sim)",
                              board->backend() == Backend::kLinux ? "linux" : "sim"));
  }
  Status s = board->AdjustConfig(config);
  if (s.ok()) s = ValidateConfig(*config);
  if (!s.ok()) return Fail(*board, "configuration", s);
  return -1;
}

// The node id LSS stored (it overrides node_id), and the store LSS writes to, if any.
NodeIdFile* OpenNodeIdStore(const Board& board, FwConfig* config) {
  if (config->lss_store[0] == '\0') return nullptr;
  static std::unique_ptr<NodeIdFile> file;
  file = std::make_unique<NodeIdFile>(config->lss_store);
  const Result<uint8_t> stored = ReadNodeIdFile(config->lss_store);
  if (stored.ok()) {
    std::fprintf(stderr, "%s: node id %u (stored by LSS in %s)\n", board.program(), *stored,
                 config->lss_store);
    config->node_id = *stored;
  } else if (stored.status().code() != StatusCode::kNotFound) {
    std::fprintf(stderr, "%s: %s; using node_id %u\n", board.program(), stored.status().message(),
                 config->node_id);
  }
  return file.get();
}

// Where the table (conveyor) lies in the left camera: table.yaml, the two keys, or the board's
// default (the simulator's rendered rig).
struct TablePoseSource {
  bool known = false;
  bool configured = false;  // by the file, not a board default
  RigidTransform left_T_table;
  // The board's default pose, read again at each recognition init (the simulator's rendered
  // table, known once its world is built), or nullptr.
  const RigidTransform* at_init = nullptr;
  bool known_now = true;  // false: the board's default pose is not known yet
};

Result<TablePoseSource> LoadTablePose(const Board& board, const FwConfig& config) {
  TablePoseSource t;
  if (config.table_file[0] != '\0') {
    SH_ASSIGN_OR_RETURN(t.left_T_table, (LoadYamlFile<RigidTransform, kMaxTableYamlBytes>(
                                            config.table_file, &ParseTableYaml)));
    t.known = t.configured = true;
  } else if (config.table_pose_set()) {
    t.left_T_table = TablePose(config);
    t.known = t.configured = true;
  } else if ((t.at_init = board.DefaultTablePose(&t.known_now)) != nullptr) {
    t.known = true;
    t.left_T_table = *t.at_init;
  }
  return t;
}

// The frame of the reported poses and the transform into it from the left camera.
struct OutputFrameChoice {
  canopen::OutputFrame frame = canopen::OutputFrame::kCamera;
  RigidTransform out_T_camera;
};

Result<OutputFrameChoice> ChooseOutputFrame(const FwConfig& config, const TablePoseSource& table) {
  OutputFrameChoice out;
  if (config.output_frame == OutputFrameKey::kTable) {
    if (!table.known || !table.known_now) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "output_frame = table needs the table pose (table_file or "
                           "table_rotation_deg/_origin_mm, or the simulator's built world)");
    }
    out.frame = canopen::OutputFrame::kTable;
    out.out_T_camera = table.left_T_table.Inverse();
  } else if (config.output_frame == OutputFrameKey::kRobot) {
    const Result<HandEye> hand_eye =
        LoadYamlFile<HandEye, kMaxHandEyeYamlBytes>(config.handeye, &ParseHandEyeYaml);
    if (!hand_eye.ok()) return hand_eye.status().WithContext("key 'handeye'");
    out.frame = hand_eye->eye_in_hand ? canopen::OutputFrame::kRobotFlange
                                      : canopen::OutputFrame::kRobotBase;
    out.out_T_camera = hand_eye->robot_T_camera;
  }
  return out;
}

// The table pose and the output frame as the boot reads them. A table_file or handeye that
// cannot be used does not stop the boot: the core comes up in fault and reports `error`
// (CoreConfig::cell_geometry), because a node missing from the bus cannot tell the PLC what is
// wrong. In its place an unknown table and the camera frame: a node in fault reports no pose.
struct CellGeometry {
  TablePoseSource table;
  OutputFrameChoice output;
  Status error;  // the first problem, naming its key and file
};

CellGeometry LoadCellGeometry(const Board& board, const FwConfig& config) {
  CellGeometry cell;
  const Result<TablePoseSource> table = LoadTablePose(board, config);
  if (table.ok()) {
    cell.table = *table;
  } else {
    cell.error = table.status().WithContext("key 'table_file'");
  }
  const Result<OutputFrameChoice> output = ChooseOutputFrame(config, cell.table);
  if (output.ok()) {
    cell.output = *output;
  } else if (cell.error.ok()) {
    // Without a table pose output_frame = table fails too: the table_file error says why.
    cell.error = output.status();
  }
  return cell;
}

// The keys the core and the recognition facade take as they are (same name; the others are
// derived from keys below).
// clang-format off
#define STEREOHASH_CORE_KEYS(X) \
  X(node_id) X(heartbeat_ms) X(capture_timeout_ms) X(budget_ms) X(free_run_dhz) \
  X(model_mask) X(sched_fifo_priority) X(result_mode) X(record_all)
// clang-format on
#define STEREOHASH_RECOGNIZER_KEYS(X) X(threads) X(table_confirm_frames) X(table_check_frames)

ObjectRecognizerConfig PipelineSettings(const FwConfig& config, const TablePoseSource& table) {
  ObjectRecognizerConfig pc;
  pc.automatic = config.background == BackgroundKey::kAuto;
  pc.light_background = config.background == BackgroundKey::kLight;
  STEREOHASH_FW_COPY_KEYS(STEREOHASH_RECOGNIZER_KEYS, config, &pc);
  // The simulator's cameras hand over grey or NV12 frames, always with a luma plane; libcamera
  // may offer only BGR888, which needs the grey images to convert into.
  pc.rgb_frames = config.camera == CameraSource::kLibcamera;
  pc.volume_set = config.volume_set();
  for (int k = 0; k < 3; ++k) {
    pc.volume_min_mm[k] = config.volume_min_mm[k];
    pc.volume_max_mm[k] = config.volume_max_mm[k];
  }
  pc.volume_in_table_frame = config.volume_frame == VolumeFrame::kTable;
  pc.volume_over_table = !pc.volume_set && table.known;
  pc.left_T_table = table.left_T_table;
  pc.left_T_table_at_init = table.at_init;
  // The table the objects stand on, for rejecting hypotheses that sink into it: a configured
  // pose only. A board's default pose (the simulated world's rendered table) bounds the volume
  // and serves the one-camera fallback, but the stereo path treats the cell as one without a
  // table file, so that the simulator runs the estimated or carried plane as such a cell does.
  pc.table_known = table.configured;
  // Without one, the plane the objects rest on: per frame, or confirmed and carried.
  pc.table_estimate = config.table_estimate != TableEstimateKey::kOff;
  pc.table_carry = config.table_estimate == TableEstimateKey::kCarry;
  // One camera needs the table for millimetre poses: any known pose, the rendered rig's too.
  pc.mono_table_known = table.known;
  // A model set as tables may carry the fallback's aspect table too.
  if (std::strcmp(config.tables, "builtin") != 0) pc.aspects_file = config.tables;
  return pc;
}

// The recognition the configuration names, with the buffers of its paths allocated here, once;
// nullptr, said on stderr, when they cannot be.
Recognition* MakeRecognition(Board* board, const FwConfig& config, FileDataSource* data,
                             const TablePoseSource& table) {
  if (config.recognition != RecognitionKind::kPipeline) {
    Recognition* other = board->OtherRecognition(config);
    if (other == nullptr) {
      (void)Fail(*board, "recognition",
                 Status::Error(StatusCode::kUnimplemented,
                               "recognition = truth exists only in stereohash-fw-sim"));
    }
    return other;
  }
  // The stereo pipeline in static storage (11 MiB; its image blocks are taken at Init). The
  // texture path's buffers (about 63 MiB) only when printed models are configured (the features
  // key, or a tables model set holding them), the one-camera fallback (1.0 MiB and its voter's
  // counters, sized by the aspect table at Init) only when configured: allocated here, once,
  // zeroed; unlocked, only the pages a frame uses become resident (docs/memory.md).
  static RecognitionPaths paths;
  const Status allocated = paths.Allocate(
      config.features[0] != '\0' || data->TablesHoldPrintedModels(), config.mono_fallback);
  if (!allocated.ok()) {
    (void)Fail(*board, "memory", allocated);
    return nullptr;
  }
  static std::unique_ptr<PipelineRecognition> pipeline_recognition;
  pipeline_recognition =
      std::make_unique<PipelineRecognition>(paths.set(), PipelineSettings(config, table));
  return pipeline_recognition.get();
}

// Recording of the triggered pairs (record_dir). A recording that cannot start (directory not
// writable) leaves the sensor working; the caller reports it as the recording warning.
Status StartRecorder(const FwConfig& config, const TablePoseSource& table,
                     canopen::OutputFrame output_frame, FileDataSource* data,
                     RecorderObserver* observer, Recorder* recorder) {
  // Copies: the boot checks load the model data again, which replaces mapped files.
  static char name_text[canopen::kMaxModelNames][kMaxModelNameLength + 1] = {};
  static const char* names[canopen::kMaxModelNames] = {};
  int n_names = 0;
  const Result<TableView> t = data->LoadTable();
  const Result<FeatureDbView> f = data->LoadFeatures();
  if (t.ok() && f.ok()) {
    const ModelSet models(&*t, nullptr, &*f);
    for (uint32_t m = 0; m < models.count() && m < canopen::kMaxModelNames; ++m) {
      std::snprintf(name_text[m], sizeof(name_text[m]), "%s", models.model(m).name);
      names[n_names++] = name_text[m];
    }
  }
  SH_ASSIGN_OR_RETURN(const StereoCalibration calibration, data->LoadCalibration());
  RecorderConfig rc;
  rc.directory = config.record_dir;
  rc.max_pairs = config.record_max;
  rc.pgm = config.record_format == RecordFormat::kPgm;
  rc.output_frame = canopen::OutputFrameName(output_frame);
  rc.background = config.background == BackgroundKey::kAuto    ? "auto"
                  : config.background == BackgroundKey::kLight ? "light"
                                                               : "dark";
  rc.model_names = names;
  rc.model_count = n_names;
  rc.settings = RecordedSettings(config, {data->tables_crc32(), data->features_crc32()});
  // table.yaml only for a configured table: recognition checks hypotheses against it. The board's
  // own table (the rendered rig's) only bounds the volume and serves one camera: rig_table.yaml,
  // which a replay takes in that role.
  if (!table.configured && table.known && table.known_now) {
    rc.rig_T_table = table.at_init != nullptr ? table.at_init : &table.left_T_table;
  }
  return recorder->Start(rc, calibration, table.configured ? &table.left_T_table : nullptr,
                         observer);
}

// The web page's server, once the core runs (nothing when http_bind is empty); HTTP_PORT=<n> on
// stdout.
Status StartWebPage(const FwConfig& config, const char* config_path, const CellGeometry& cell,
                    FirmwareCore* core, const Recorder* recorder, const BoardDevices& devices,
                    FileDataSource* data, web::WebService* web_page) {
  if (config.http_bind[0] == '\0') return Status::Ok();
  // The rig for the overlays: without one the page shows the images and results alone.
  static StereoCalibration calibration;
  const Result<StereoCalibration> loaded = data->LoadCalibration();
  if (loaded.ok()) calibration = *loaded;
  web::WebService::Running running;
  running.core = core;
  running.recorder = recorder;
  running.can = devices.can;
  running.camera = devices.camera;
  running.calibration = loaded.ok() ? &calibration : nullptr;
  running.output_frame = canopen::OutputFrameName(cell.output.frame);
  // The box the pipeline bounds its features with, when one is configured: in the camera, or
  // on the table (the board's default pose read now, once the simulated world is built).
  static RigidTransform left_T_volume;
  if (config.volume_set() && config.volume_frame == VolumeFrame::kCamera) {
    left_T_volume = RigidTransform();
    running.left_T_volume = &left_T_volume;
  } else if (config.volume_set() && cell.table.known) {
    left_T_volume = cell.table.at_init != nullptr ? *cell.table.at_init : cell.table.left_T_table;
    running.left_T_volume = &left_T_volume;
  }
  running.config_path = config_path != nullptr ? config_path : "";
  return web_page->Start(config, running, stdout);
}

}  // namespace

bool StopRequested() { return g_stop != 0; }

int FirmwareMain(int argc, char** argv, Board* board) {
  static FwConfig config;
  config = board->Defaults();
  long run_seconds = 0;
  const char* config_path = nullptr;
  const int exit_code = ParseOptions(argc, argv, board, &config, &run_seconds, &config_path);
  if (exit_code >= 0) return exit_code;
  // Before any thread starts: every thread's stack is locked in full by mlock.
  {
    const Status s = LimitThreadStacks();
    if (!s.ok()) std::fprintf(stderr, "%s: %s\n", board->program(), s.message());
  }
  signal(SIGTERM, OnSignal);
  signal(SIGINT, OnSignal);
  signal(SIGPIPE, SIG_IGN);

  static SdNotifier notifier;
  {
    const Status s = notifier.Open();
    if (!s.ok()) std::fprintf(stderr, "%s: %s\n", board->program(), s.message());
  }
  NodeIdFile* lss_store = OpenNodeIdStore(*board, &config);
  const uint32_t serial_number = config.serial_number != 0 ? config.serial_number : MachineSerial();

  // --- devices ---------------------------------------------------------------------------
  BoardDevices devices;
  {
    const Status s = board->OpenDevices(config, &devices);
    if (!s.ok()) return Fail(*board, "devices", s);
  }
  // candump log of everything the firmware sends and receives.
  static FILE* candump = nullptr;
  static std::unique_ptr<hal::CandumpLogger> logger;
  if (config.candump[0] != '\0') {
    candump = std::fopen(config.candump, "w");
    if (candump == nullptr) {
      return Fail(*board, "candump",
                  Status::Error(StatusCode::kNotFound, "cannot write %s", config.candump));
    }
    logger = std::make_unique<hal::CandumpLogger>(devices.can, candump, true);
    devices.can = logger.get();
  }

  // --- data, table pose, output frame, recognition ----------------------------------------
  static std::unique_ptr<FileDataSource> data;
  data = std::make_unique<FileDataSource>(config.tables, config.calibration,
                                          board->BuiltinCalibration());
  data->SetFeaturesPath(config.features);
  data->PinIdentity(config.tables_crc32, config.features_crc32);
  const CellGeometry cell = LoadCellGeometry(*board, config);

  Recognition* recognition = MakeRecognition(board, config, data.get(), cell.table);
  if (recognition == nullptr) return 1;

  PrefaultStack();

  // The web page's snapshot sees the boot's model data, so it exists before the core starts.
  static web::WebService web_page;
  const Result<CoreObserver*> web_observer = web_page.Prepare(config, cell.output.out_T_camera);
  if (!web_observer.ok()) return Fail(*board, "web page", web_observer.status());
  static MainObserver observer(&notifier, board->Observer(config, cell.output.frame),
                               *web_observer);
  {
    const Status s = board->BeforeStart(config, data.get());
    if (!s.ok()) return Fail(*board, "start", s);
  }
  CoreConfig cc;
  STEREOHASH_FW_COPY_KEYS(STEREOHASH_CORE_KEYS, config, &cc);
  cc.output_frame = cell.output.frame;
  cc.out_T_camera = cell.output.out_T_camera;
  cc.cell_geometry = cell.error;
  cc.serial_number = serial_number;
  cc.hardware_version = board->hardware_version();
  // Locked by the core once it has started (docs/memory.md, "Locked memory").
  cc.lock_memory = config.mlock;
  CoreDevices core_devices;
  core_devices.can = devices.can;
  core_devices.gpio = devices.gpio;
  core_devices.camera = devices.camera;
  core_devices.recognition = recognition;
  core_devices.data = data.get();
  core_devices.observer = &observer;
  core_devices.lss_store = lss_store;
  static FirmwareCore core;
  static Recorder recorder;
  Status recording = Status::Ok();
  if (config.record_dir[0] != '\0') {
    recording = StartRecorder(config, cell.table, cell.output.frame, data.get(), &core, &recorder);
    if (recording.ok()) {
      core_devices.recorder = &recorder;
    } else {
      std::fprintf(stderr, "%s: recording off: %s\n", board->program(), recording.message());
    }
  }
  const Status started = core.Start(cc, core_devices);
  if (!started.ok()) return Fail(*board, "start", started);
  if (!recording.ok())
    core.OnRecordFailed(recorder.start_error() != 0 ? recorder.start_error() : EIO);
  {
    // The sensor's work goes on without its page: said on stderr, not a reason to stop.
    const Status s = StartWebPage(config, config_path, cell, &core, core_devices.recorder, devices,
                                  data.get(), &web_page);
    if (!s.ok()) std::fprintf(stderr, "%s: web page off: %s\n", board->program(), s.message());
  }
  board->AfterStart(config, core, *data);
  (void)notifier.Notify(core.state() == FirmwareState::kFault ? "READY=1\nSTATUS=fault"
                                                              : "READY=1\nSTATUS=ready");

  const int64_t end_ns = run_seconds > 0 ? MonotonicNs() + run_seconds * 1'000'000'000ll : 0;
  while (!g_stop && (end_ns == 0 || MonotonicNs() < end_ns)) usleep(50'000);

  (void)notifier.Notify("STOPPING=1");
  web_page.Stop();
  core.Stop();
  recorder.Stop();  // writes what the last triggers submitted
  board->Stop();
  if (candump != nullptr) std::fclose(candump);
  return 0;
}

}  // namespace sh::fw
