// stereohash-fw: the vision board program. `--config FILE` on the board (backend = linux) or in
// the simulator (backend = sim); `--sim` starts the simulator with built-in defaults.
//
// Simulator stdout (one line each, flushed), used by tests/python/test_firmware_e2e.py:
//   SOCKETCAND_PORT=<n>      the socketcand server on 127.0.0.1 listens
//   MODELS {json}            model names and symmetries by model id
//   READY                    boot finished (state follows in STATE lines)
//   STATE <n>                firmware state changes (0 init, 1 ready, 2 busy, 3 fault)
//   RESULT {json}            every result set sent, with the ground truth of its frame
//   EMCY {json}              every EMCY sent
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "firmware/data_source.hpp"
#include "firmware/demo_client.hpp"
#include "firmware/firmware_core.hpp"
#include "firmware/fw_config.hpp"
#include "firmware/node_id_file.hpp"
#include "firmware/realtime.hpp"
#include "firmware/recorder.hpp"
#include "firmware/sd_notify.hpp"
#include "firmware/truth_recognition.hpp"
#include "hal/can_log.hpp"
#include "hal/linux/socketcan_bus.hpp"
#include "hal/sim/can_sim_bus.hpp"
#include "hal/sim/directory_camera.hpp"
#include "hal/sim/gpio_sim.hpp"
#include "hal/sim/sim_camera.hpp"
#include "hal/sim/socketcand_server.hpp"
#include "recog/base/crc32.hpp"
#include "recog/camera/handeye_yaml.hpp"
#include "recog/camera/table_yaml.hpp"
#ifdef STEREOHASH_FW_HAVE_PIPELINE
#include "firmware/pipeline_recognition.hpp"
#endif
#ifdef STEREOHASH_FW_HAVE_LIBCAMERA
#include "hal/linux/libcamera_camera.hpp"
#endif
#ifdef STEREOHASH_FW_HAVE_GPIOD
#include "hal/linux/gpiod_gpio.hpp"
#endif

namespace {

using namespace sh;
using namespace sh::fw;

// Where LSS stores the node id on the board unless `lss_store` says otherwise (the systemd unit's
// StateDirectory).
constexpr const char* kDefaultNodeIdFile = "/var/lib/stereohash/node-id";

volatile sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

void Usage() {
  std::printf(
      "usage: stereohash-fw --config FILE        run with a configuration file\n"
      "       stereohash-fw --sim [--config FILE] simulator (built-in defaults, FILE on top)\n"
      "       stereohash-fw --sim --demo          simulator plus an in-process PLC printing the\n"
      "                                           poses as they arrive over the simulated bus\n"
      "options: --run-seconds S (stop after S seconds), --help\n"
      "Configuration keys: docs/firmware.md; examples in share/stereohash/*.conf.example.\n");
}

// Model directory for the simulator: the config, else next to the installed binary
// (<prefix>/bin/../share/stereohash/models), else the source tree this binary was built from.
void DefaultModelsDir(char* out, size_t capacity) {
  char exe[512];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof(exe) - 1);
  if (n > 0) {
    exe[n] = '\0';
    char* slash = std::strrchr(exe, '/');
    if (slash != nullptr) {
      *slash = '\0';
      std::snprintf(out, capacity, "%s/../share/stereohash/models", exe);
      if (access(out, R_OK) == 0) return;
    }
  }
  std::snprintf(out, capacity, "%s", STEREOHASH_FW_SOURCE_MODELS_DIR);
}

// stdout reporting of the simulator and the systemd watchdog.
class Reporter final : public CoreObserver {
 public:
  Reporter(const render::SimWorld* world, SdNotifier* notifier, bool print,
           canopen::OutputFrame frame)
      : world_(world), notifier_(notifier), print_(print), frame_(frame) {}

  // The models of the tables just loaded (at boot, and again when a data fault is cleared).
  void OnDataLoaded(const TableView& t) override {
    if (!print_) return;
    std::printf("MODELS {\"names\": [");
    for (uint32_t m = 0; m < t.model_count(); ++m) {
      std::printf("%s\"%s\"", m ? ", " : "", t.model(m).name);
    }
    std::printf("], \"symmetries\": [");
    for (uint32_t m = 0; m < t.model_count(); ++m) {
      const Model& model = t.model(m);
      std::printf("%s[", m ? ", " : "");
      for (int s = 0; s < model.n_symmetries; ++s) {
        std::printf("%s[", s ? ", " : "");
        for (int k = 0; k < 9; ++k) std::printf("%s%.9g", k ? ", " : "", model.symmetries[s][k]);
        std::printf("]");
      }
      std::printf("]");
    }
    // Corner centroids: symmetries map the corners onto themselves, so they fix the centroid,
    // which makes it the point to compare positions of symmetric objects at.
    std::printf("], \"centroids_mm\": [");
    for (uint32_t m = 0; m < t.model_count(); ++m) {
      const Model& model = t.model(m);
      double c[3] = {0, 0, 0};
      for (int i = 0; i < model.n_corners; ++i) {
        for (int k = 0; k < 3; ++k) c[k] += model.corners_mm[i][k] / model.n_corners;
      }
      std::printf("%s[%.6f, %.6f, %.6f]", m ? ", " : "", c[0], c[1], c[2]);
    }
    std::printf("]}\n");
    std::fflush(stdout);
    if (world_ != nullptr) MapWorldModelsToTable(*world_, t, table_ids_);
  }

  void OnResult(const protocol::ResultSet& set, const hal::StereoFrame* frame) override {
    if (!print_) return;
    std::printf(
        "RESULT {\"sequence\": %u, \"request_id\": %u, \"status\": %u, "
        "\"processing_time_us\": %u, \"output_frame\": \"%s\", \"objects\": [",
        set.sequence, set.request_id, static_cast<unsigned>(set.status), set.processing_time_us,
        canopen::OutputFrameName(frame_));
    for (int i = 0; i < set.object_count; ++i) {
      const protocol::ObjectPose& p = set.objects[i];
      std::printf(
          "%s{\"model_id\": %u, \"instance\": %u, \"score\": %.17g, "
          "\"t_mm\": [%.17g, %.17g, %.17g], \"q_wxyz\": [%.17g, %.17g, %.17g, %.17g]}",
          i ? ", " : "", p.model_id, p.instance, p.score, p.cam_t_model_mm[0], p.cam_t_model_mm[1],
          p.cam_t_model_mm[2], p.cam_q_model[0], p.cam_q_model[1], p.cam_q_model[2],
          p.cam_q_model[3]);
    }
    std::printf("]");
    if (frame != nullptr) {
      std::printf(", \"frame\": %u, \"pair_index\": %llu", frame->left_sequence,
                  static_cast<unsigned long long>(frame->pair_index));
    }
    if (frame != nullptr && world_ != nullptr) {
      const int scene = world_->SceneOfFrame(frame->left_sequence);
      const render::GeneratedScene& g = world_->scene(scene);
      std::printf(", \"scene\": %d, \"truth\": [", scene);
      for (size_t i = 0; i < g.scene.objects.size(); ++i) {
        const RigidTransform& T = g.left_T_model[i];
        std::printf("%s{\"model_id\": %d, \"t_mm\": [%.6f, %.6f, %.6f], \"R\": [", i ? ", " : "",
                    table_ids_[g.scene.objects[i].model_index], T.t_mm.x(), T.t_mm.y(), T.t_mm.z());
        for (int k = 0; k < 9; ++k) std::printf("%s%.9f", k ? ", " : "", T.R(k / 3, k % 3));
        std::printf("]}");
      }
      std::printf("]");
    }
    std::printf("}\n");
    std::fflush(stdout);
  }

  void OnEmcy(const protocol::Emcy& e) override {
    if (!print_) return;
    std::printf(
        "EMCY {\"error_code\": %u, \"error_register\": %u, \"state\": %u, \"detail\": %u}\n",
        e.error_code, e.error_register, static_cast<unsigned>(e.state), e.detail);
    std::fflush(stdout);
  }

  void OnStateChange(FirmwareState s) override {
    if (!print_) return;
    std::printf("STATE %u\n", static_cast<unsigned>(s));
    std::fflush(stdout);
  }

  void OnAlive() override { (void)notifier_->Notify("WATCHDOG=1"); }

 private:
  const render::SimWorld* world_;
  SdNotifier* notifier_;
  bool print_;
  canopen::OutputFrame frame_;
  int table_ids_[kMaxFolderModels] = {};
};

// The simulator rig's calibration for the data source: known once the world is built.
class WorldCalibration final : public RigCalibration {
 public:
  explicit WorldCalibration(render::SimWorld* world) : world_(world) {}
  Result<StereoCalibration> Calibration() override { return world_->Calibration(); }

 private:
  render::SimWorld* world_;
};

int Fail(const char* what, const Status& s) {
  std::fprintf(stderr, "stereohash-fw: %s: %s\n", what, s.message());
  return 1;
}

// A small text file (table pose, hand-eye) into `text`; kOutOfRange if it does not fit.
Status ReadTextFile(const char* path, char* text, size_t capacity, size_t* length) {
  std::FILE* f = std::fopen(path, "rb");
  if (f == nullptr) {
    return Status::Error(StatusCode::kNotFound, "cannot open %s: %s", path, std::strerror(errno));
  }
  const size_t n = std::fread(text, 1, capacity, f);
  const bool more = std::fgetc(f) != EOF;
  std::fclose(f);
  if (more)
    return Status::Error(StatusCode::kOutOfRange, "%s is larger than %zu bytes", path, capacity);
  *length = n;
  return Status::Ok();
}

bool FileExists(const char* path) { return access(path, R_OK) == 0; }

// A small YAML file (table pose, hand-eye) read and parsed; errors name the file. Boot only.
template <typename T, size_t kBytes>
Result<T> LoadYamlFile(const char* path, Result<T> (*parse)(const char*, size_t)) {
  static char text[kBytes];
  size_t n = 0;
  SH_RETURN_IF_ERROR(ReadTextFile(path, text, sizeof(text), &n));
  Result<T> parsed = parse(text, n);
  if (!parsed.ok()) return parsed.status().WithContext("%s", path);
  return parsed;
}

// dir/name into out; false if it does not fit.
bool JoinPath(char* out, size_t capacity, const char* dir, const char* name) {
  const int n = std::snprintf(out, capacity, "%s/%s", dir, name);
  return n >= 0 && static_cast<size_t>(n) < capacity;
}

// A serial number that differs between boards without configuration: CRC-32 of the machine id
// systemd keeps in /etc/machine-id (0 if there is none).
uint32_t MachineSerial() {
  char id[64] = {};
  size_t n = 0;
  if (!ReadTextFile("/etc/machine-id", id, sizeof(id) - 1, &n).ok()) return 0;
  while (n > 0 && (id[n - 1] == '\n' || id[n - 1] == ' ')) --n;
  return n > 0 ? Crc32(id, n) : 0;
}

}  // namespace

int main(int argc, char** argv) {
  const char* config_path = nullptr;
  bool sim = false, demo = false;
  long run_seconds = 0;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--config") && i + 1 < argc) {
      config_path = argv[++i];
    } else if (!std::strcmp(argv[i], "--sim")) {
      sim = true;
    } else if (!std::strcmp(argv[i], "--demo")) {
      demo = true;
    } else if (!std::strcmp(argv[i], "--run-seconds") && i + 1 < argc) {
      run_seconds = std::strtol(argv[++i], nullptr, 10);
    } else if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      Usage();
      return 0;
    } else {
      std::fprintf(stderr, "stereohash-fw: unknown argument '%s' (see --help)\n", argv[i]);
      return 2;
    }
  }
  if (!sim && config_path == nullptr) {
    Usage();
    return 2;
  }
  if (demo && !sim) {
    std::fprintf(stderr, "stereohash-fw: --demo needs --sim\n");
    return 2;
  }
  static FwConfig config;
  config = sim ? SimDefaults() : FwConfig();
  if (config_path != nullptr) {
    const Status s = LoadConfigFile(config_path, &config);
    if (!s.ok()) return Fail("configuration", s);
  }
  if (sim) config.backend = Backend::kSim;
  if (demo) {
    config.sim_print_truth = false;
    if (config.free_run_dhz == 0) config.free_run_dhz = 10;  // 1 Hz
  }
  {
    const Status s = ValidateConfig(config);
    if (!s.ok()) return Fail("configuration", s);
  }
  signal(SIGTERM, OnSignal);
  signal(SIGINT, OnSignal);
  signal(SIGPIPE, SIG_IGN);

  static SdNotifier notifier;
  {
    const Status s = notifier.Open();
    if (!s.ok()) std::fprintf(stderr, "stereohash-fw: %s\n", s.message());
  }
  const bool is_sim = config.backend == Backend::kSim;
  const bool replay = config.camera == CameraSource::kDirectory;
  if (replay) {
    // A recorded set (scene folders with left/right, calib.yaml and table.yaml beside them)
    // brings its own calibration and table pose unless the configuration names others.
    char table_yaml[kConfigPathMax];
    if ((config.calibration_path[0] == '\0' &&
         !JoinPath(config.calibration_path, sizeof(config.calibration_path),
                   config.camera_directory, "calib.yaml")) ||
        !JoinPath(table_yaml, sizeof(table_yaml), config.camera_directory, "table.yaml")) {
      return Fail("configuration",
                  Status::Error(StatusCode::kInvalidArgument, "camera_directory %s is too long",
                                config.camera_directory));
    }
    if (config.table_file[0] == '\0' && !config.table_pose_set && FileExists(table_yaml)) {
      std::memcpy(config.table_file, table_yaml, sizeof(config.table_file));
    }
    if (config.recognition == RecognitionKind::kTruth) {
      return Fail("configuration", Status::Error(StatusCode::kInvalidArgument,
                                                 "recognition = truth needs the rendered scenes, "
                                                 "not camera = directory"));
    }
  }

  // --- node id stored by LSS, serial number ------------------------------------------------
  static char node_id_path[kConfigPathMax];
  std::snprintf(node_id_path, sizeof(node_id_path), "%s",
                config.lss_store_set ? config.lss_store_path
                : is_sim             ? ""
                                     : kDefaultNodeIdFile);
  static std::unique_ptr<NodeIdFile> node_id_file;
  if (node_id_path[0] != '\0') {
    node_id_file = std::make_unique<NodeIdFile>(node_id_path);
    const Result<uint8_t> stored = ReadNodeIdFile(node_id_path);
    if (stored.ok()) {
      std::fprintf(stderr, "stereohash-fw: node id %u (stored by LSS in %s)\n", *stored,
                   node_id_path);
      config.node_id = *stored;
    } else if (stored.status().code() != StatusCode::kNotFound) {
      std::fprintf(stderr, "stereohash-fw: %s; using node_id %u\n", stored.status().message(),
                   config.node_id);
    }
  }
  const uint32_t serial_number = config.serial_number != 0 ? config.serial_number : MachineSerial();

  // --- backends ---------------------------------------------------------------------------
  static hal::SimCanBus sim_bus;
  static hal::SocketcandServer socketcand;
  static hal::SocketCanBus socketcan;
  static hal::SimGpio sim_gpio;
  static render::SimWorld world;
  static std::unique_ptr<hal::SimCamera> sim_camera;
  static DemoClient demo_client;
  hal::CanBus* can = nullptr;
  hal::Gpio* gpio = nullptr;
  hal::StereoCamera* camera = nullptr;

  // No receive filter: LSS may give the node another id at run time, and the core takes only the
  // identifiers of its current id (NMT, LSS, RPDOs, SDO) from what arrives.
  static std::unique_ptr<hal::DirectoryCamera> directory_camera;
  if (replay) {
    hal::DirectoryCameraConfig dc;
    dc.directory = config.camera_directory;
    dc.loop = true;  // each trigger plays the next pair, from the first again after the last
    directory_camera = std::make_unique<hal::DirectoryCamera>(dc);
  }
  if (is_sim) {
    hal::SimCanEndpointConfig ep;
    ep.name = config.can_interface;
    Result<hal::SimCanEndpoint*> fw_ep = sim_bus.AddEndpoint(ep);
    if (!fw_ep.ok()) return Fail("sim CAN", fw_ep.status());
    can = *fw_ep;
    hal::SocketcandServerConfig sc;
    sc.port = static_cast<uint16_t>(config.sim_port);
    // fw_config.cpp bounds sim_socketcand_clients by this capacity without seeing the server.
    static_assert(hal::kSocketcandMaxClients == 16,
                  "sim_socketcand_clients range in fw_config.cpp");
    sc.max_clients = static_cast<size_t>(config.sim_socketcand_clients);
    sc.handshake_timeout_ms = config.sim_socketcand_handshake_ms;
    sc.idle_timeout_ms = config.sim_socketcand_idle_ms;
    sc.stall_timeout_ms = config.sim_socketcand_stall_ms;
    sc.channel = config.can_interface;
    const Status s = socketcand.Start(&sim_bus, sc);
    if (!s.ok()) return Fail("socketcand server", s);
    std::printf("SOCKETCAND_PORT=%u\n", socketcand.port());
    std::fflush(stdout);

    static char models_dir[kConfigPathMax];
    if (config.models_dir[0] != '\0') {
      std::snprintf(models_dir, sizeof(models_dir), "%s", config.models_dir);
    } else {
      DefaultModelsDir(models_dir, sizeof(models_dir));
    }
    if (replay) {
      camera = directory_camera.get();
    } else {
      render::SimWorldConfig wc;
      wc.models_dir = models_dir;
      wc.seed = config.sim_seed;
      wc.scenes = config.sim_scenes;
      wc.objects = config.sim_objects;
      wc.light_background = config.sim_light_background;
      // A world that cannot be built (no model folder) is a fault, not an exit: the camera and
      // the calibration report it, and a clear-fault tries again.
      world.Configure(wc);
      const Status built = world.EnsureBuilt();
      if (!built.ok()) {
        std::fprintf(stderr, "stereohash-fw: simulator scenes: %s\n", built.message());
      }
      hal::SimCameraConfig cc;
      if (config.sim_camera_fault == SimCameraFault::kRightSilent) cc.right_stop_after = 3;
      if (config.sim_camera_fault == SimCameraFault::kDropRight) cc.drop_right_every = 3;
      sim_camera = std::make_unique<hal::SimCamera>(&world, cc);
      camera = sim_camera.get();
    }
    gpio = &sim_gpio;
  } else {
    hal::SocketCanConfig sc;
    sc.interface = config.can_interface;
    const Status s = socketcan.Open(sc);
    if (!s.ok()) return Fail("CAN", s);
    can = &socketcan;
    if (replay) {
      camera = directory_camera.get();
    } else {
#ifdef STEREOHASH_FW_HAVE_LIBCAMERA
      hal::LibcameraStereoConfig lc;
      lc.left_id = config.camera_left_id;
      lc.right_id = config.camera_right_id;
      lc.left_index = config.camera_left_index;
      lc.right_index = config.camera_right_index;
      lc.width = config.camera_width;
      lc.height = config.camera_height;
      static std::unique_ptr<hal::LibcameraStereoCamera> lcam;
      lcam = std::make_unique<hal::LibcameraStereoCamera>(lc);
      camera = lcam.get();
#else
      return Fail("camera",
                  Status::Error(StatusCode::kUnimplemented, "this build has no libcamera backend"));
#endif
    }
    const bool gpio_wired = config.gpio_trigger_line >= 0 || config.gpio_ready_line >= 0 ||
                            config.gpio_busy_line >= 0 || config.gpio_strobe_line >= 0;
    if (gpio_wired) {
#ifdef STEREOHASH_FW_HAVE_GPIOD
      static hal::GpiodGpio gpiod;
      hal::GpiodConfig gc;
      gc.chip = config.gpio_chip;
      gc.trigger_line = config.gpio_trigger_line;
      gc.ready_line = config.gpio_ready_line;
      gc.busy_line = config.gpio_busy_line;
      gc.strobe_line = config.gpio_strobe_line;
      gc.outputs_active_low = config.gpio_outputs_active_low;
      gc.trigger_active_low = config.gpio_trigger_active_low;
      const Status g = gpiod.Open(gc);
      if (!g.ok()) return Fail("GPIO", g);
      gpio = &gpiod;
#else
      return Fail("GPIO", Status::Error(StatusCode::kUnimplemented,
                                        "gpio lines configured but this build has no libgpiod"));
#endif
    }
  }

  // candump log of everything the firmware sends and receives.
  static FILE* candump = nullptr;
  static std::unique_ptr<hal::CandumpLogger> logger;
  if (config.candump_path[0] != '\0') {
    candump = std::fopen(config.candump_path, "w");
    if (candump == nullptr) {
      return Fail("candump",
                  Status::Error(StatusCode::kNotFound, "cannot write %s", config.candump_path));
    }
    logger = std::make_unique<hal::CandumpLogger>(can, candump, true);
    can = logger.get();
  }

  // --- data and recognition --------------------------------------------------------------
  static WorldCalibration world_calibration(&world);
  static std::unique_ptr<FileDataSource> data;
  data = std::make_unique<FileDataSource>(config.tables_path, config.calibration_path,
                                          is_sim && !replay ? &world_calibration : nullptr);

  // The table (conveyor) pose: table.yaml, the two config keys, or the rendered rig's table
  // (known once the simulator's world is built: recognition reads it at each init).
  bool table_known = false;
  RigidTransform left_T_table;
  if (config.table_file[0] != '\0') {
    const Result<RigidTransform> pose =
        LoadYamlFile<RigidTransform, kMaxTableYamlBytes>(config.table_file, &ParseTableYaml);
    if (!pose.ok()) return Fail("table_file", pose.status());
    left_T_table = *pose;
    table_known = true;
  } else if (config.table_pose_set) {
    left_T_table = TablePose(config);
    table_known = true;
  } else if (is_sim && !replay) {
    left_T_table = world.left_T_table();
    table_known = true;
  }
  const bool table_from_world =
      table_known && is_sim && !replay && config.table_file[0] == '\0' && !config.table_pose_set;

  // The frame of the reported poses.
  canopen::OutputFrame output_frame = canopen::OutputFrame::kCamera;
  RigidTransform out_T_camera;
  if (config.output_frame == OutputFrameKey::kTable) {
    if (!table_known || (table_from_world && !world.built())) {
      return Fail("configuration", Status::Error(StatusCode::kInvalidArgument,
                                                 "output_frame = table needs the table pose "
                                                 "(table_file or table_rotation_deg/_origin_mm, "
                                                 "or the simulator's built world)"));
    }
    output_frame = canopen::OutputFrame::kTable;
    out_T_camera = left_T_table.Inverse();
  } else if (config.output_frame == OutputFrameKey::kRobot) {
    const Result<HandEye> hand_eye =
        LoadYamlFile<HandEye, kMaxHandEyeYamlBytes>(config.handeye_path, &ParseHandEyeYaml);
    if (!hand_eye.ok()) return Fail("handeye", hand_eye.status());
    output_frame = hand_eye->eye_in_hand ? canopen::OutputFrame::kRobotFlange
                                         : canopen::OutputFrame::kRobotBase;
    out_T_camera = hand_eye->robot_T_camera;
  }
  data->InjectCorruptTables(config.sim_corrupt_tables && is_sim);

  static std::unique_ptr<Recognition> recognition;
  if (config.recognition == RecognitionKind::kTruth) {
    recognition = std::make_unique<TruthRecognition>(&world);
  } else {
#ifdef STEREOHASH_FW_HAVE_PIPELINE
    static Pipeline pipeline;  // tens of MiB: static storage, locked and pre-faulted below
    PipelineRecognitionConfig pc;
    // The board measures its thresholds unless a preset is configured; the simulator keeps the
    // preset of the background it renders unless `background` says otherwise. A replayed set
    // is recognised as the board (and `stereohash recognize`) would.
    const bool rendered = is_sim && !replay;
    pc.automatic = !config.background_set && !rendered;
    pc.light_background =
        config.background_set ? config.light_background : rendered && config.sim_light_background;
    pc.threads = config.threads;
    // The simulator's default box belongs to the rendered table; a replayed set is bounded
    // like `stereohash recognize --table` bounds it, over its own table.
    pc.volume_set = config.volume_set && !(replay && config.volume_is_sim_default);
    for (int k = 0; k < 3; ++k) {
      pc.volume_min_mm[k] = config.volume_min_mm[k];
      pc.volume_max_mm[k] = config.volume_max_mm[k];
    }
    pc.volume_in_table_frame = config.volume_in_table_frame;
    pc.volume_over_table = !pc.volume_set && table_known;
    pc.left_T_table = left_T_table;
    if (table_from_world) pc.left_T_table_at_init = &world.left_T_table();
    // The table the objects stand on, for rejecting hypotheses that sink into it: a configured
    // pose only. The simulator's scenes tilt the rig differently, so scene 0's table bounds the
    // volume but is not every scene's support plane.
    pc.table_known = table_known && (config.table_file[0] != '\0' || config.table_pose_set);
    recognition = std::make_unique<PipelineRecognition>(&pipeline, pc);
#else
    return Fail("recognition", Status::Error(StatusCode::kUnimplemented,
                                             "this build has no recognition pipeline; use "
                                             "recognition = truth in the simulator"));
#endif
  }

  if (config.mlock) {
    const Status s = LockMemory();
    if (!s.ok()) std::fprintf(stderr, "stereohash-fw: %s; continuing unlocked\n", s.message());
  }
  PrefaultStack();

  static Reporter reporter(is_sim && !replay ? &world : nullptr, &notifier,
                           is_sim && config.sim_print_truth, output_frame);
  if (demo) {
    // Copies: the boot checks load the tables again, which replaces a mapped file.
    static char name_text[kMaxTableModels][kMaxModelNameLength + 1] = {};
    static const char* names[kMaxTableModels] = {};
    const Result<TableView> t = data->LoadTable();
    int n_names = 0;
    if (t.ok()) {
      for (uint32_t m = 0; m < t->model_count() && m < kMaxTableModels; ++m) {
        std::snprintf(name_text[m], sizeof(name_text[m]), "%s", t->model(m).name);
        names[n_names++] = name_text[m];
      }
    }
    const Status s = demo_client.Start(&sim_bus, config.node_id, names, n_names);
    if (!s.ok()) return Fail("demo client", s);
  }
  if (is_sim && config.sim_wait_for_client) {
    while (socketcand.raw_mode_clients() == 0 && !g_stop) usleep(2000);
  }

  CoreConfig cc;
  cc.node_id = config.node_id;
  cc.heartbeat_ms = config.heartbeat_ms;
  cc.capture_timeout_ms = config.capture_timeout_ms;
  cc.budget_ms = config.budget_ms;
  cc.free_run_dhz = config.free_run_dhz;
  cc.model_mask = config.model_mask;
  cc.sched_fifo_priority = config.sched_fifo_priority;
  cc.result_mode = static_cast<canopen::ResultMode>(config.result_mode);
  cc.output_frame = output_frame;
  cc.out_T_camera = out_T_camera;
  cc.serial_number = serial_number;
  cc.hardware_version = is_sim ? "stereohash simulator" : "stereohash vision board";
  CoreDevices devices;
  devices.lss_store = node_id_file.get();
  devices.can = can;
  devices.gpio = gpio;
  devices.camera = camera;
  devices.recognition = recognition.get();
  devices.data = data.get();
  devices.observer = &reporter;
  static FirmwareCore core;

  // Recording of the triggered pairs. A recording that cannot start (directory not writable)
  // leaves the sensor working and says so with the recording warning.
  static Recorder recorder;
  Status recording = Status::Ok();
  if (config.record_dir[0] != '\0') {
    static const char* names[canopen::kMaxModelNames] = {};
    int n_names = 0;
    const Result<TableView> t = data->LoadTable();
    if (t.ok()) {
      for (uint32_t m = 0; m < t->model_count() && m < canopen::kMaxModelNames; ++m) {
        names[n_names++] = t->model(m).name;
      }
    }
    const Result<StereoCalibration> calib = data->LoadCalibration();
    RecorderConfig rc;
    rc.directory = config.record_dir;
    rc.max_pairs = config.record_max;
    rc.pgm = config.record_pgm;
    rc.output_frame = canopen::OutputFrameName(output_frame);
    rc.model_names = names;
    rc.model_count = n_names;
    // table.yaml only for a configured table: recognition checks hypotheses against it, so a
    // recording replays as recognised (the rendered rig's table only bounds the volume).
    const bool table_configured = config.table_file[0] != '\0' || config.table_pose_set;
    recording = calib.ok() ? recorder.Start(rc, *calib, table_configured ? &left_T_table : nullptr,
                                            &core)
                           : calib.status();
    if (recording.ok()) {
      devices.recorder = &recorder;
    } else {
      std::fprintf(stderr, "stereohash-fw: recording off: %s\n", recording.message());
    }
  }
  const Status started = core.Start(cc, devices);
  if (!started.ok()) return Fail("start", started);
  if (!recording.ok()) core.OnRecordFailed(EIO);
  if (is_sim && config.sim_print_truth) {
    std::printf("READY\n");
    std::fflush(stdout);
  }
  (void)notifier.Notify(core.state() == FirmwareState::kFault ? "READY=1\nSTATUS=fault"
                                                              : "READY=1\nSTATUS=ready");

  const int64_t end_ns = run_seconds > 0 ? MonotonicNs() + run_seconds * 1'000'000'000ll : 0;
  while (!g_stop && (end_ns == 0 || MonotonicNs() < end_ns)) usleep(50'000);

  (void)notifier.Notify("STOPPING=1");
  core.Stop();
  recorder.Stop();  // writes what the last triggers submitted
  demo_client.Stop();
  if (is_sim) socketcand.Stop();
  if (candump != nullptr) std::fclose(candump);
  return 0;
}
