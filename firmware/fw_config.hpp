// Configuration of stereohash-fw: a plain `key = value` text file (docs/firmware.md lists every
// key). Parsing never throws and never allocates: strings live in fixed arrays, and the first
// problem is reported with its line number and key.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::fw {

inline constexpr size_t kConfigPathMax = 256;
inline constexpr size_t kConfigNameMax = 64;
inline constexpr size_t kMaxConfigFileBytes = size_t{64} * 1024;
inline constexpr int kMaxRecordPairs = 10000;  // record_max limit

enum class Backend : uint8_t { kLinux, kSim };
enum class RecognitionKind : uint8_t {
  kPipeline,  // the recognition pipeline (the product)
  kTruth,     // simulator only: reports the rendered ground truth (exercises CAN and timing paths)
};
// Simulated camera faults, injected from the start (tests inject them at run time instead).
enum class SimCameraFault : uint8_t { kNone, kRightSilent, kDropRight };
// Where the images come from: the backend's cameras (libcamera on the board, the rendered
// scenes in the simulator) or recorded stereo pairs played from a directory.
enum class CameraSource : uint8_t { kBackend, kDirectory };
// Frame of the reported poses (CAN output frame byte: 0, 1, and 2 or 3 after the hand-eye file).
enum class OutputFrameKey : uint8_t { kCamera, kTable, kRobot };

struct FwConfig {
  Backend backend = Backend::kSim;
  char can_interface[16] = "can0";
  uint8_t node_id = 1;
  uint32_t heartbeat_ms = 200;  // 0 (off) or 10..10000
  uint8_t result_mode = 0;      // canopen::ResultMode: 0 stream, 1 pdo, 2 both
  uint32_t serial_number = 0;   // 0x1018 sub 4; 0 = derived from /etc/machine-id
  // LSS store: the node id file written by the LSS "store configuration" service and read at
  // boot (it overrides node_id). "" = store not supported.
  char lss_store_path[kConfigPathMax] = "";
  bool lss_store_set = false;

  // Cameras (linux backend): libcamera ids take precedence over indices.
  char camera_left_id[kConfigNameMax] = "";
  char camera_right_id[kConfigNameMax] = "";
  int camera_left_index = 0;
  int camera_right_index = 1;
  int camera_width = 1280;
  int camera_height = 800;
  int capture_timeout_ms = 500;
  CameraSource camera = CameraSource::kBackend;
  char camera_directory[kConfigPathMax] = "";  // camera = directory: recorded-scenes layout

  // Data. calibration: empty = the simulator's built-in rig (sim only). tables: "builtin" = the
  // tables linked into the binary, else a table blob file.
  char calibration_path[kConfigPathMax] = "";
  char tables_path[kConfigPathMax] = "builtin";
  char models_dir[kConfigPathMax] = "";  // OBJ models for the simulator renderer; "" = default

  RecognitionKind recognition = RecognitionKind::kPipeline;
  uint16_t budget_ms = 1000;           // kTimeBudgetMinMs..kTimeBudgetMaxMs
  uint16_t free_run_dhz = 0;           // 0.1 Hz, 0 = off
  uint32_t model_mask = 0xFFFFFFFFu;   // masked to the loaded models at boot
  bool volume_set = false;             // working volume box, mm, in volume_frame
  bool volume_is_sim_default = false;  // the box over the rendered table (SimDefaults)
  float volume_min_mm[3] = {-1000, -1000, 100};
  float volume_max_mm[3] = {1000, 1000, 3000};
  // The box's frame: the left camera, or the table (conveyor) whose pose in the left camera is
  // table_rotation_deg (rotation vector, degrees) and table_origin_mm. In the simulator a table
  // volume without a pose takes the rendered rig's table.
  bool volume_in_table_frame = false;
  bool table_pose_set = false;
  float table_rotation_deg[3] = {0, 0, 0};
  float table_origin_mm[3] = {0, 0, 0};
  bool light_background = false;  // pipeline preset; `background` key, in sim: sim_background
  bool background_set = false;    // `background = dark|light`; `auto` (default) measures
  int threads = 0;  // pipeline worker threads, the calling one included; 0 = all cores
  // table.yaml (R_table, t_table) instead of table_rotation_deg / table_origin_mm.
  char table_file[kConfigPathMax] = "";
  OutputFrameKey output_frame = OutputFrameKey::kCamera;
  char handeye_path[kConfigPathMax] = "";  // output_frame = robot: from calibrate-handeye

  // Recording of triggered pairs with their results (record_dir "" = off).
  char record_dir[kConfigPathMax] = "";
  int record_max = 100;  // the last N pairs are kept
  bool record_pgm = false;  // record_format = pgm

  // GPIO (linux backend; -1 = not wired).
  char gpio_chip[kConfigNameMax] = "gpiochip0";
  int gpio_trigger_line = -1;
  int gpio_ready_line = -1;
  int gpio_busy_line = -1;
  int gpio_strobe_line = -1;
  bool gpio_outputs_active_low = false;
  bool gpio_trigger_active_low = false;

  // Real time.
  bool mlock = true;
  int sched_fifo_priority = 0;  // 0 = normal scheduling, 1..99 = SCHED_FIFO for the worker

  // Simulator.
  int sim_port = 0;                        // socketcand TCP port on 127.0.0.1; 0 = ephemeral
  int sim_socketcand_clients = 4;          // client slots, 1..16
  int sim_socketcand_handshake_ms = 2000;  // connect to raw mode, else the slot is freed
  int sim_socketcand_idle_ms = 0;          // raw-mode client silent this long: closed (0 = never)
  int sim_socketcand_stall_ms = 2000;      // client not reading this long: closed
  uint64_t sim_seed = 1;
  bool sim_light_background = false;
  int sim_objects = 3;
  int sim_scenes = 6;  // distinct scenes rendered at boot and cycled through
  SimCameraFault sim_camera_fault = SimCameraFault::kNone;
  bool sim_corrupt_tables = false;   // boot with a damaged copy of the tables (fault demo)
  bool sim_wait_for_client = false;  // boot only once a socketcand client is in raw mode
  bool sim_print_truth = true;       // RESULT lines with ground truth on stdout

  char candump_path[kConfigPathMax] = "";  // log of all CAN traffic; "" = none
};

// Built-in simulator defaults (`stereohash-fw --sim`).
FwConfig SimDefaults();

// Parses `text` (need not be NUL-terminated) on top of the values already in *config. Lines:
// `key = value`, `#` starts a comment, blank lines are skipped. Unknown keys, repeated keys,
// malformed values and out-of-range numbers fail with "line N: key 'k': ...".
Status ParseConfig(const char* text, size_t length, FwConfig* config);

// Reads and parses a file (at most kMaxConfigFileBytes) on top of *config, then validates.
Status LoadConfigFile(const char* path, FwConfig* config);

// The table (conveyor) frame in the left camera from table_rotation_deg / table_origin_mm:
// x_left = R(rotation vector) x_table + origin.
RigidTransform TablePose(const FwConfig& c);

// Checks combinations (linux backend needs a calibration file, ...).
Status ValidateConfig(const FwConfig& config);

}  // namespace sh::fw
