// The simulator board (stereohash-fw-sim): the simulated CAN bus with a socketcand server on
// 127.0.0.1, simulated GPIO, and as cameras the simulated world (scenes rendered at boot) or
// recorded pairs played from a directory (camera = directory); and what only a simulator has:
// ground-truth recognition, stdout lines with the truth, injected faults and the in-process demo
// PLC (--demo).
//
// Simulator stdout (one line each, flushed), used by tests/python/test_firmware_e2e.py:
//   SOCKETCAND_PORT=<n>      the socketcand server on 127.0.0.1 listens
//   MODELS {json}            model names and symmetries by model id
//   READY                    boot finished (state follows in STATE lines)
//   STATE <n>                firmware state changes (0 init, 1 ready, 2 busy, 3 fault)
//   RESULT {json}            every result set sent, with the ground truth of its frame
//   EMCY {json}              every EMCY sent
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>

#include "firmware/board.hpp"
#include "firmware/demo_client.hpp"
#include "firmware/recorded_settings.hpp"
#include "firmware/result_json.hpp"
#include "firmware/sim_config.hpp"
#include "firmware/truth_recognition.hpp"
#include "hal/sim/can_sim_bus.hpp"
#include "hal/sim/directory_camera.hpp"
#include "hal/sim/gpio_sim.hpp"
#include "hal/sim/sim_camera.hpp"
#include "hal/sim/socketcand_server.hpp"
#include "hal/sim/world/sim_world.hpp"
#include "recog/base/printable.hpp"
#include "recog/camera/table_yaml.hpp"
#include "tables/input_file.hpp"

namespace sh::fw {
namespace {

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
      // An installed path longer than `out` is not used (a cut path could name another folder).
      const int len = std::snprintf(out, capacity, "%s/../share/stereohash/models", exe);
      if (len > 0 && size_t(len) < capacity && access(out, R_OK) == 0) return;
    }
  }
  std::snprintf(out, capacity, "%s", STEREOHASH_FW_SOURCE_MODELS_DIR);
}

// dir/name into out; false if it does not fit.
bool JoinPath(char* out, size_t capacity, const char* dir, const char* name) {
  const int n = std::snprintf(out, capacity, "%s/%s", dir, name);
  return n >= 0 && static_cast<size_t>(n) < capacity;
}

// The simulator's stdout lines (tests/python/test_firmware_e2e.py reads them).
class Reporter final : public CoreObserver {
 public:
  // world: the rendered scenes whose truth RESULT lines carry, or nullptr (replay).
  Reporter(const render::SimWorld* world, bool print, canopen::OutputFrame frame)
      : world_(world), print_(print), frame_(frame) {}

  // The models just loaded (tables, then the printed models; at boot, and again when a data
  // fault is cleared).
  void OnDataLoaded(const ModelSet& models) override {
    if (!print_) return;
    const uint32_t n = models.count();
    std::printf("MODELS {\"names\": [");
    for (uint32_t m = 0; m < n; ++m) {
      char name[kJsonNameBytes];
      const char* raw = models.model(m).name;
      std::printf("%s\"%s\"", m ? ", " : "",
                  JsonEscaped(raw, sizeof(Model::name), name, sizeof(name)));
    }
    std::printf("], \"symmetries\": [");
    for (uint32_t m = 0; m < n; ++m) {
      const Model& model = models.model(m);
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
    for (uint32_t m = 0; m < n; ++m) {
      const Model& model = models.model(m);
      double c[3] = {0, 0, 0};
      for (int i = 0; i < model.n_corners; ++i) {
        for (int k = 0; k < 3; ++k) c[k] += model.corners_mm[i][k] / model.n_corners;
      }
      std::printf("%s[%.6f, %.6f, %.6f]", m ? ", " : "", c[0], c[1], c[2]);
    }
    std::printf("]}\n");
    std::fflush(stdout);
    if (world_ != nullptr) MapWorldModelsToIds(*world_, models, table_ids_);
  }

  void OnResult(const protocol::ResultSet& set, const hal::StereoFrame* frame) override {
    if (!print_) return;
    std::printf("RESULT {");
    protocol::WriteResultSetJsonFields(stdout, set);
    std::printf(", \"output_frame\": \"%s\"", canopen::OutputFrameName(frame_));
    std::printf(", \"table\": \"%s\"", protocol::TablePlaneName(set.table));
    // The frame number of the camera in use (the right one's alone when the left has failed).
    const uint32_t frame_number = frame == nullptr              ? 0
                                  : frame->left.data != nullptr ? frame->left_sequence
                                                                : frame->right_sequence;
    if (frame != nullptr) {
      std::printf(", \"frame\": %u, \"pair_index\": %llu", frame_number,
                  static_cast<unsigned long long>(frame->pair_index));
    }
    if (frame != nullptr && world_ != nullptr) {
      const int scene = world_->SceneOfFrame(frame_number);
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

 private:
  const render::SimWorld* world_;
  bool print_;
  canopen::OutputFrame frame_;
  int table_ids_[render::kMaxWorldModels] = {};
};

class SimBoard final : public Board {
 public:
  const char* program() const override { return "stereohash-fw-sim"; }
  Backend backend() const override { return Backend::kSim; }
  const char* hardware_version() const override { return "stereohash simulator"; }
  FwConfig Defaults() const override { return SimDefaults(); }
  bool NeedsConfigFile() const override { return false; }

  int ParseOption(int argc, char** argv, int i) override {
    if (!std::strcmp(argv[i], "--demo")) {
      demo_ = true;
      return 1;
    }
    return 0;
  }
  void PrintOptions(std::FILE* out) const override {
    std::fprintf(out,
                 "        --demo: an in-process PLC printing the poses as they arrive over the "
                 "simulated bus\n");
  }

  Status AdjustConfig(FwConfig* config) const override {
    // The pipeline preset follows the rendered table unless the file sets it (`background = auto`
    // too: the board's automatic detection on rendered scenes); a replayed set is recognised as
    // its recording was (settings.conf), or as the board would, automatically.
    if (!config->Given(ConfigKeyId::background) && config->camera != CameraSource::kDirectory) {
      config->background = config->sim_background == TableSurface::kLight ? BackgroundKey::kLight
                                                                          : BackgroundKey::kDark;
    }
    if (demo_) {
      config->sim_print_truth = false;
      if (config->free_run_dhz == 0) config->free_run_dhz = 10;  // 1 Hz
    }
    if (config->camera == CameraSource::kDirectory) SH_RETURN_IF_ERROR(AdjustForReplay(config));
    return Status::Ok();
  }

  Status OpenDevices(const FwConfig& config, BoardDevices* devices) override {
    hal::SimCanEndpointConfig ep;
    ep.name = config.can_interface;
    SH_ASSIGN_OR_RETURN(devices->can, bus_.AddEndpoint(ep));
    hal::SocketcandServerConfig sc;
    sc.port = static_cast<uint16_t>(config.sim_port);
    // config_keys.hpp bounds sim_socketcand_clients by this capacity without seeing the server.
    static_assert(hal::kSocketcandMaxClients == 16, "sim_socketcand_clients range in config_keys");
    sc.max_clients = static_cast<size_t>(config.sim_socketcand_clients);
    sc.handshake_timeout_ms = config.sim_socketcand_handshake_ms;
    sc.idle_timeout_ms = config.sim_socketcand_idle_ms;
    sc.stall_timeout_ms = config.sim_socketcand_stall_ms;
    sc.channel = config.can_interface;
    SH_RETURN_IF_ERROR(socketcand_.Start(&bus_, sc).WithContext("socketcand server"));
    std::printf("SOCKETCAND_PORT=%u\n", socketcand_.port());
    std::fflush(stdout);
    devices->gpio = &gpio_;

    if (config.camera == CameraSource::kDirectory) {
      hal::DirectoryCameraConfig dc;
      dc.directory = config.camera_directory;
      dc.loop = true;  // each trigger plays the next pair, from the first again after the last
      directory_camera_ = std::make_unique<hal::DirectoryCamera>(dc);
      devices->camera = directory_camera_.get();
      // Without its table the replay still runs, bounded as a cell without a table file is.
      const Status rig = LoadRigTable(config);
      if (!rig.ok()) std::fprintf(stderr, "%s: replay: %s\n", program(), rig.message());
      return Status::Ok();
    }
    if (config.models_dir[0] != '\0') {
      std::snprintf(models_dir_, sizeof(models_dir_), "%s", config.models_dir);
    } else {
      DefaultModelsDir(models_dir_, sizeof(models_dir_));
    }
    render::SimWorldConfig wc;
    wc.models_dir = models_dir_;
    wc.printed_dir = config.sim_printed_models;
    wc.colour_dir = config.sim_colour_models;
    wc.seed = config.sim_seed;
    wc.scenes = config.sim_scenes;
    wc.objects = config.sim_objects;
    wc.light_background = config.sim_background == TableSurface::kLight;
    // A world that cannot be built (no model folder) is a fault, not an exit: the camera and the
    // calibration report it, and a clear-fault tries again.
    world_.Configure(wc);
    rendered_ = true;
    const Status built = world_.EnsureBuilt();
    if (!built.ok()) std::fprintf(stderr, "%s: simulator scenes: %s\n", program(), built.message());
    hal::SimCameraConfig cc;
    if (config.sim_camera_fault == SimCameraFault::kRightSilent ||
        config.sim_camera_fault == SimCameraFault::kLeftSilent) {
      (config.sim_camera_fault == SimCameraFault::kRightSilent ? cc.right_stop_after
                                                               : cc.left_stop_after) = 3;
      cc.fault_starts = 1;  // back once the firmware restarts the camera (clear-fault)
    }
    if (config.sim_camera_fault == SimCameraFault::kDropRight) cc.drop_right_every = 3;
    if (config.sim_camera_fault == SimCameraFault::kRightAbsent ||
        config.sim_camera_fault == SimCameraFault::kLeftAbsent) {
      (config.sim_camera_fault == SimCameraFault::kRightAbsent ? cc.right_absent : cc.left_absent) =
          true;
      cc.fault_starts = 1;  // plugged in by the time the firmware restarts the camera
    }
    camera_ = std::make_unique<hal::SimCamera>(&world_, cc);
    devices->camera = camera_.get();
    return Status::Ok();
  }

  RigCalibration* BuiltinCalibration() override {
    return rendered_ ? &world_calibration_ : nullptr;
  }
  const RigidTransform* DefaultTablePose(bool* known_now) const override {
    if (replayed_rig_table_) return &rig_T_table_;  // the table the recording was bounded by
    if (!rendered_) return nullptr;
    *known_now = world_.built();
    return &world_.left_T_table();  // the rendered rig's table
  }
  Recognition* OtherRecognition(const FwConfig& config) override {
    truth_ = std::make_unique<TruthRecognition>(&world_);
    return truth_.get();
  }
  CoreObserver* Observer(const FwConfig& config, canopen::OutputFrame output_frame) override {
    return &reporter_.emplace(rendered_ ? &world_ : nullptr, config.sim_print_truth, output_frame);
  }

  Status BeforeStart(const FwConfig& config, FileDataSource* data) override {
    data->InjectCorruptTables(config.sim_corrupt_tables);
    if (demo_) {
      // Copies: the boot checks load the model data again, which replaces mapped files.
      const Result<TableView> t = data->LoadTable();
      const Result<FeatureDbView> f = data->LoadFeatures();
      const Result<ShapeViewsView> v = data->LoadShapeViews();
      n_names_ = 0;
      if (t.ok() && f.ok() && v.ok()) {
        const ModelSet models(&*t, &*v, &*f);
        for (uint32_t m = 0; m < models.count() && m < canopen::kMaxModelNames; ++m) {
          std::snprintf(name_text_[m], sizeof(name_text_[m]), "%s", models.model(m).name);
          names_[n_names_++] = name_text_[m];
        }
      }
      SH_RETURN_IF_ERROR(demo_client_.Start(&bus_, config.node_id, names_, n_names_));
    }
    if (config.sim_wait_for_client) {
      while (socketcand_.raw_mode_clients() == 0 && !StopRequested()) usleep(2000);
    }
    return Status::Ok();
  }

  void AfterStart(const FwConfig& config, const FirmwareCore& core,
                  const FileDataSource& data) override {
    if (config.sim_print_truth) {
      std::printf("READY\n");
      std::fflush(stdout);
    }
  }

  void Stop() override {
    demo_client_.Stop();
    socketcand_.Stop();
  }

 private:
  // A recorded set (scene folders with left/right, calib.yaml and table.yaml beside them) brings
  // its own calibration and table pose unless the configuration names others; the default box
  // belongs to the rendered table, so a replayed set is bounded over its own table, as
  // `stereohash recognize --table` bounds it.
  static Status AdjustForReplay(FwConfig* config) {
    char table_yaml[kConfigPathMax];
    if ((config->calibration[0] == '\0' &&
         !JoinPath(config->calibration, sizeof(config->calibration), config->camera_directory,
                   "calib.yaml")) ||
        !JoinPath(table_yaml, sizeof(table_yaml), config->camera_directory, "table.yaml")) {
      return Status::Error(StatusCode::kInvalidArgument, "camera_directory %s is too long",
                           config->camera_directory);
    }
    if (config->table_file[0] == '\0' && !config->table_pose_set() &&
        access(table_yaml, R_OK) == 0) {
      std::memcpy(config->table_file, table_yaml, sizeof(config->table_file));
    }
    if (config->volume_is_sim_default()) config->sim_volume_box = false;
    return ApplyRecordedSettings(config);
  }

  // A recording's settings.conf gives the settings its results were recognised with (preset,
  // working volume, table estimate, one-camera fallback: recorded_settings.hpp). The replay takes
  // each that its own file does not give, or its edges and poses differ from the recorded ones.
  static Status ApplyRecordedSettings(FwConfig* config) {
    char path[kConfigPathMax];
    if (!JoinPath(path, sizeof(path), config->camera_directory, "settings.conf")) {
      return Status::Error(StatusCode::kInvalidArgument, "camera_directory %s is too long",
                           config->camera_directory);
    }
    if (access(path, R_OK) != 0) return Status::Ok();
    static FwConfig recorded;  // large: kept off the stack, read once at boot
    recorded = SimDefaults();
    SH_RETURN_IF_ERROR(LoadConfigFile(path, &recorded));
    TakeRecordedSettings(recorded, config);
    return Status::Ok();
  }

  // A recording of the simulator carries the rendered table its volume was bounded by and its
  // one-camera fallback measured on (rig_table.yaml): the replay's own table in that same role,
  // unless the configuration gives one.
  Status LoadRigTable(const FwConfig& config) {
    char path[kConfigPathMax];
    if (!JoinPath(path, sizeof(path), config.camera_directory, "rig_table.yaml")) {
      return Status::Error(StatusCode::kInvalidArgument, "camera_directory %s is too long",
                           config.camera_directory);
    }
    if (access(path, R_OK) != 0) return Status::Ok();
    static char text[kMaxTableYamlBytes];
    size_t n = 0;
    SH_RETURN_IF_ERROR(ReadInputFile(path, "table pose", text, sizeof(text), &n));
    const Result<RigidTransform> pose = ParseTableYaml(text, n);
    if (!pose.ok()) return pose.status().WithContext("%s", path);
    rig_T_table_ = *pose;
    replayed_rig_table_ = true;
    return Status::Ok();
  }

  bool demo_ = false;
  hal::SimCanBus bus_;
  hal::SocketcandServer socketcand_;
  hal::SimGpio gpio_;
  // The simulator rig's calibration for the data source: known once the world is built.
  class WorldCalibration final : public RigCalibration {
   public:
    explicit WorldCalibration(render::SimWorld* world) : world_(world) {}
    Result<StereoCalibration> Calibration() override { return world_->Calibration(); }

   private:
    render::SimWorld* world_;
  };

  render::SimWorld world_;
  WorldCalibration world_calibration_{&world_};
  bool rendered_ = false;            // the cameras are the simulated world's (not recorded pairs)
  RigidTransform rig_T_table_;       // a replayed recording's rig_table.yaml
  bool replayed_rig_table_ = false;  // ... read
  std::unique_ptr<hal::SimCamera> camera_;
  std::unique_ptr<hal::DirectoryCamera> directory_camera_;
  std::unique_ptr<TruthRecognition> truth_;
  std::optional<Reporter> reporter_;
  DemoClient demo_client_;
  char models_dir_[kConfigPathMax] = {};
  char name_text_[canopen::kMaxModelNames][kMaxModelNameLength + 1] = {};
  const char* names_[canopen::kMaxModelNames] = {};
  int n_names_ = 0;
};

}  // namespace
}  // namespace sh::fw

int main(int argc, char** argv) {
  static sh::fw::SimBoard board;
  return sh::fw::FirmwareMain(argc, argv, &board);
}
