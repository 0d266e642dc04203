// The configuration keys of stereohash-fw and stereohash-fw-sim, declared once: each line of
// STEREOHASH_FW_CONFIG_KEYS gives a key's name (also its FwConfig field), type, default, range
// and help. That one list declares the FwConfig fields with their defaults (fw_config.hpp) and
// the table (config_keys.cpp) that drives parsing and its range errors, the programs' --help
// and the key table of docs/firmware.md (`--config-keys-markdown`, checked by the
// firmware_config_docs test). The simulator's defaults are the board's with the changes of
// SimDefaults() (sim_config.cpp), printed from it.
//
// Key kinds (the macro each line uses):
//   INT(name, type, default, min, max, unit, help)         integer in min..max
//   INT_OR_OFF(name, type, default, min, max, unit, help)  0 (off) or min..max
//   MASK(name, type, default, help)                        32-bit mask, not 0 (hex)
//   CRC32(name, help)                           0 (not checked) or a CRC-32 in hex, uint32_t
//   BOOL(name, default, help)                              true/yes/on/1, false/no/off/0
//   CHOICE(name, type, default, "a|b|c", help)  one of the names; `type` is a one-byte enum
//                                               whose enumerators are the names in order
//   TEXT(name, capacity, default, help)         text of up to capacity - 1 characters
//   VEC3(name, x, y, z, unit, help)             three numbers (spaces or commas between)
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "firmware/canopen/cob_id.hpp"
#include "firmware/canopen/od_table.hpp"
#include "firmware/command_codec.hpp"
#include "recog/base/status.hpp"

namespace sh::fw {

inline constexpr size_t kConfigPathMax = 256;
inline constexpr size_t kConfigNameMax = 64;
inline constexpr size_t kConfigInterfaceMax = 16;  // IFNAMSIZ
inline constexpr size_t kConfigAddressMax = 48;    // an IPv6 address as text (INET6_ADDRSTRLEN)
inline constexpr int kMaxRecordPairs = 10000;      // record_max limit
inline constexpr int kMaxConfigThreads = 8;        // kMaxPoolThreads of recog/pipeline

// The values of the choice keys, in the order of their names.
enum class Backend : uint8_t { kLinux, kSim };
enum class RecognitionKind : uint8_t {
  kPipeline,  // the recognition pipeline (the product)
  kTruth,     // simulator only: reports the rendered ground truth (exercises CAN and timing paths)
};
// Simulated camera faults, injected from the start (tests inject them at run time instead).
enum class SimCameraFault : uint8_t {
  kNone,
  kRightSilent,
  kDropRight,
  kLeftSilent,
  kRightAbsent,
  kLeftAbsent,
};
// Where the images come from: the board's cameras (libcamera), the simulated world's, or
// recorded stereo pairs played from a directory (the simulator program).
enum class CameraSource : uint8_t { kLibcamera, kSim, kDirectory };
// Frame of the reported poses (CAN output frame byte: 0, 1, and 2 or 3 after the hand-eye file).
enum class OutputFrameKey : uint8_t { kCamera, kTable, kRobot };
// Detector thresholds: measured from each image, or a preset for a dark or light table.
enum class BackgroundKey : uint8_t { kAuto, kDark, kLight };
enum class TableSurface : uint8_t { kDark, kLight };  // the simulator's rendered table
enum class VolumeFrame : uint8_t { kCamera, kTable };
// Without a table pose: no table, the plane estimated in every frame, or estimated, confirmed
// over a few frames and carried (recog/pipeline/table_carry.hpp).
enum class TableEstimateKey : uint8_t { kOff, kPerFrame, kCarry };
enum class RecordFormat : uint8_t { kPng, kPgm };

// clang-format off
#define STEREOHASH_FW_CONFIG_KEYS(INT, INT_OR_OFF, MASK, CRC32, BOOL, CHOICE, TEXT, VEC3)          \
  CHOICE(backend, Backend, Backend::kLinux, "linux|sim",                                           \
         "the program this file is for: linux (stereohash-fw: SocketCAN, libgpiod, libcamera) "    \
         "or sim (stereohash-fw-sim)")                                                             \
  TEXT(can_interface, kConfigInterfaceMax, "can0",                                                 \
       "SocketCAN interface (the socketcand channel name in the simulator)")                       \
  INT(node_id, uint8_t, 1, protocol::kNodeIdMin, protocol::kNodeIdMax, "",                         \
      "CANopen node id (a node id stored by LSS takes precedence)")                                \
  INT_OR_OFF(heartbeat_ms, uint32_t, 200, 10, 10000, "ms",                                         \
             "power-on producer heartbeat time (0x1017)")                                          \
  CHOICE(result_mode, canopen::ResultMode, canopen::ResultMode::kStream, "stream|pdo|both",         \
         "results as the multiplexed stream, in the PDO mode or both (0x2000 sub 4; "              \
         "can-protocol.md)")                                                                       \
  INT(serial_number, uint32_t, 0, 0, 0xFFFFFFFFll, "",                                             \
      "0x1018 sub 4 and the LSS identity; 0 = CRC-32 of /etc/machine-id (differs per board)")      \
  TEXT(lss_store, kConfigPathMax, "/var/lib/stereohash/node-id",                                   \
       "file the LSS store configuration service writes and the boot reads; empty = store not "    \
       "supported")                                                                                \
  CHOICE(camera, CameraSource, CameraSource::kLibcamera, "libcamera|sim|directory",                \
         "the board's cameras (libcamera), the simulated world's (sim), or recorded pairs from "   \
         "camera_directory (directory, stereohash-fw-sim)")                                        \
  TEXT(camera_directory, kConfigPathMax, "",                                                       \
       "recorded-scenes folder for camera = directory (docs/firmware.md, Replay)")                 \
  CHOICE(output_frame, OutputFrameKey, OutputFrameKey::kCamera, "camera|table|robot",              \
         "frame of the reported poses: camera, table (needs the table pose) or robot (needs "      \
         "handeye)")                                                                               \
  TEXT(handeye, kConfigPathMax, "", "hand-eye file of stereohash calibrate-handeye")               \
  TEXT(table_file, kConfigPathMax, "",                                                             \
       "table.yaml (R_table, t_table; stereohash calibrate-table) instead of "                     \
       "table_rotation_deg/table_origin_mm; a configured table pose also rejects hypotheses "      \
       "sinking more than 5 mm into the table")                                                    \
  TEXT(camera_left_id, kConfigNameMax, "",                                                         \
       "libcamera id of the left camera (cam --list); takes precedence over the index")            \
  TEXT(camera_right_id, kConfigNameMax, "", "libcamera id of the right camera")                    \
  INT(camera_left_index, int, 0, 0, 15, "", "libcamera index of the left camera")                  \
  INT(camera_right_index, int, 1, 0, 15, "", "libcamera index of the right camera")                \
  INT(camera_width, int, 1280, 16, 2592, "px",                                                     \
      "sensor width as calibrated; above 1296 the camera is asked for frames binned to fit "        \
      "(kMaxImageWidth, kMaxSensorWidth)")                                                         \
  INT(camera_height, int, 800, 16, 2048, "px",                                                     \
      "sensor height as calibrated; above 1024 frames are binned alike (kMaxImageHeight, "          \
      "kMaxSensorHeight)")                                                                         \
  INT(capture_timeout_ms, int, 500, 10, 60000, "ms", "how long a capture waits for a stereo pair") \
  TEXT(calibration, kConfigPathMax, "",                                                            \
       "stereo calibration YAML; required on the board; empty in the simulator = the rendered "    \
       "rig (with camera = directory: the set's calib.yaml)")                                      \
  TEXT(tables, kConfigPathMax, "builtin",                                                          \
       "builtin (the tables linked into the program), a model set (stereohash tables build; "      \
       "its HASH3D section, and its TEXTURE_FEATURES section unless features is set) or a table "  \
       "blob file (mapped)")                                                                       \
  TEXT(features, kConfigPathMax, "",                                                               \
       "feature database of printed cartons (a model set or a feature database file), mapped; "    \
       "their model ids follow the tables' models; empty = the tables' model set's, if any")       \
  CRC32(tables_crc32,                                                                              \
        "the CRC-32 the tables must carry, as `stereohash tables info` prints it (for builtin: "   \
        "the linked-in tables'); other tables are a data fault. A recording pins its own")         \
  CRC32(features_crc32,                                                                            \
        "the CRC-32 the features file must carry (tables info); other files are a data fault")     \
  TEXT(models_dir, kConfigPathMax, "",                                                             \
       "simulator: the model folder it renders; empty = the installed share/stereohash/models, "   \
       "else the source tree's models/")                                                           \
  CHOICE(recognition, RecognitionKind, RecognitionKind::kPipeline, "pipeline|truth",               \
         "the recognition pipeline, or (simulator only) the rendered ground truth, which tests "   \
         "the CAN and timing path")                                                                \
  INT(budget_ms, uint16_t, 1000, protocol::kTimeBudgetMinMs, protocol::kTimeBudgetMaxMs, "ms",     \
      "time budget of one recognition")                                                            \
  INT(free_run_dhz, uint16_t, 0, 0, protocol::kFreeRunRateMaxDeciHz, "0.1 Hz",                     \
      "free-run trigger rate, 0 = off")                                                            \
  MASK(model_mask, uint32_t, 0xFFFFFFFFu,                                                          \
       "initial model set, bit m = model id m (masked to the loaded models)")                      \
  VEC3(volume_min_mm, -1000, -1000, 100, "mm",                                                     \
       "working volume box, lower corner in volume_frame: 3-D features outside are dropped")       \
  VEC3(volume_max_mm, 1000, 1000, 3000, "mm", "working volume box, upper corner")                  \
  CHOICE(volume_frame, VolumeFrame, VolumeFrame::kCamera, "camera|table",                          \
         "frame of the box: the left camera (OpenCV axes) or the table (conveyor); without a "     \
         "box and with a table pose, the space over the table as stereohash recognize --table "    \
         "uses")                                                                                   \
  VEC3(table_rotation_deg, 0, 0, 0, "deg",                                                         \
       "table (conveyor) frame in the left camera: rotation vector, x_left = R x_table + origin; " \
       "the simulator's default is its rendered rig's table")                                      \
  VEC3(table_origin_mm, 0, 0, 0, "mm",                                                             \
       "table frame in the left camera: origin; z up from the belt keeps reflections out")         \
  CHOICE(table_estimate, TableEstimateKey, TableEstimateKey::kCarry, "off|per_frame|carry",        \
         "without a table pose: off (no table), per_frame (the plane the objects found rest on, "  \
         "estimated in each frame and searched again) or carry (estimated until "                  \
         "table_confirm_frames estimates agree, then carried: one search per frame, checked and "  \
         "re-estimated when it stops fitting)")                                                    \
  INT(table_confirm_frames, uint16_t, 3, 1, 100, "frames",                                         \
      "table_estimate = carry: agreeing estimates in a row (normals within 1 deg, origins within " \
      "2 mm) before the plane is carried")                                                         \
  INT(table_check_frames, uint16_t, 50, 0, 10000, "frames",                                        \
      "table_estimate = carry: carried frames between two checks by a fresh estimate; 0 = only "   \
      "after a frame whose objects do not rest on the plane")                                      \
  BOOL(mono_fallback, true,                                                                        \
       "pipeline recognition: a camera that fails leaves the other recognising alone (the "        \
       "one-camera fallback, its 1.7 MiB allocated at boot); false: a silent camera is the "       \
       "capture fault")                                                                            \
  CHOICE(background, BackgroundKey, BackgroundKey::kAuto, "auto|dark|light",                       \
         "auto: detector thresholds measured from each image; dark or light force a preset "       \
         "(the simulator's rendered scenes: the preset of sim_background)")                                   \
  INT(threads, int, 0, 0, kMaxConfigThreads, "",                                                   \
      "pipeline worker threads, the calling one included; 0 = all online cores")                   \
  TEXT(record_dir, kConfigPathMax, "",                                                             \
       "folder for recordings of triggered pairs with their results; empty = off")                 \
  INT(record_max, int, 100, 1, kMaxRecordPairs, "", "recordings kept (the last ones)")             \
  CHOICE(record_format, RecordFormat, RecordFormat::kPng, "png|pgm",                                \
         "image files of the recordings: png (libpng's fast deflate), or pgm (raw: several "       \
         "times faster to write, about twice as large)")                                           \
  BOOL(record_all, true,                                                                           \
       "record_dir: keep every triggered pair; false: only the pairs asked for on the web page "   \
       "(record the next N pairs)")                                                                \
  TEXT(http_bind, kConfigAddressMax, "",                                                           \
       "address the commissioning web page listens on (docs/web.md): 127.0.0.1 = this machine "    \
       "only, 0.0.0.0 = every interface, an IPv6 address; empty = no web server")                 \
  INT(http_port, int, 8080, 0, 65535, "",                                                          \
      "port of the web page; 0 = ephemeral (printed as HTTP_PORT=<n>)")                            \
  TEXT(http_password, kConfigNameMax, "",                                                          \
       "password of the web page's actions and settings; without it and http_password_file the "  \
       "page is read-only")                                                                        \
  TEXT(http_password_file, kConfigPathMax, "",                                                     \
       "file holding a crypt(3) hash of the web password (mkpasswd -m sha-512, openssl passwd "   \
       "-6) instead of http_password")                                                             \
  TEXT(http_tls_cert, kConfigPathMax, "",                                                          \
       "PEM certificate (chain) of the web page; with http_tls_key the page is served over HTTPS "  \
       "only (docs/web.md)")                                                                       \
  TEXT(http_tls_key, kConfigPathMax, "",                                                           \
       "PEM private key of http_tls_cert (unencrypted; readable by the firmware's user only)")      \
  TEXT(gpio_chip, kConfigNameMax, "gpiochip0", "GPIO chip (name, path, label or number)")          \
  INT(gpio_trigger_line, int, -1, -1, 1023, "", "trigger input line offset, -1 = not wired")       \
  INT(gpio_ready_line, int, -1, -1, 1023, "", "ready output line, -1 = not wired")                 \
  INT(gpio_busy_line, int, -1, -1, 1023, "", "busy output line, -1 = not wired")                   \
  INT(gpio_strobe_line, int, -1, -1, 1023, "", "strobe output line, -1 = not wired")               \
  BOOL(gpio_outputs_active_low, false, "wiring polarity of the outputs")                           \
  BOOL(gpio_trigger_active_low, false, "wiring polarity of the trigger")                           \
  BOOL(mlock, true,                                                                                \
       "lock every page mapped once the firmware has started, and again after a data reload or "   \
       "a camera restart (mlockall(MCL_CURRENT), docs/memory.md); refused = a warning")            \
  INT(sched_fifo_priority, int, 0, 0, 99, "",                                                      \
      "SCHED_FIFO priority of the worker thread, 0 = normal scheduling")                           \
  INT(sim_port, int, 0, 0, 65535, "",                                                              \
      "socketcand port on 127.0.0.1, 0 = ephemeral (printed as SOCKETCAND_PORT=<n>)")              \
  INT(sim_socketcand_clients, int, 4, 1, 16, "",                                                   \
      "socketcand client slots, 65 KiB of buffers each (hal::kSocketcandMaxClients)")              \
  INT(sim_socketcand_handshake_ms, int, 2000, 1, 600000, "ms",                                     \
      "a client not in raw mode this long after connecting is closed")                             \
  INT(sim_socketcand_idle_ms, int, 0, 0, 600000, "ms",                                             \
      "a raw-mode client that sent nothing this long is closed; 0 = never (listen-only clients "   \
      "are fine)")                                                                                 \
  INT(sim_socketcand_stall_ms, int, 2000, 1, 600000, "ms",                                         \
      "a client whose output stayed full (it does not read) this long is closed, its lost "        \
      "frames logged")                                                                             \
  INT(sim_seed, uint64_t, 1, 0, 0x7FFFFFFFFFFFFFFFll, "",                                          \
      "first scene seed (seeds that cannot place the objects are skipped)")                        \
  CHOICE(sim_background, TableSurface, TableSurface::kDark, "dark|light", "the rendered table")    \
  INT(sim_objects, int, 3, 1, 16, "", "objects per scene (kMaxRenderObjects)")                     \
  TEXT(sim_printed_models, kConfigPathMax, "",                                                     \
       "folder of printed models (OBJ, MTL, artwork) the scenes also place, drawn with their "     \
       "print, e.g. models/textured; empty = none")                                                \
  TEXT(sim_colour_models, kConfigPathMax, "",                                                      \
       "folder of single-colour parts (OBJ + MTL with a Kd) the scenes also place, drawn in "      \
       "their colour; the cameras then deliver NV12 frames, e.g. models/colour; empty = none")      \
  INT(sim_scenes, int, 6, 1, 64, "", "scenes rendered at boot; frame n shows scene n mod count")   \
  CHOICE(sim_camera_fault, SimCameraFault, SimCameraFault::kNone,                                 \
         "none|right_silent|drop_right|left_silent|right_absent|left_absent",                      \
         "right_silent (left_silent): that camera stops after 3 frames until the firmware "        \
         "restarts it (clear-fault); drop_right: every 3rd right frame is lost; right_absent "     \
         "(left_absent): that camera is not connected at boot, and is at the next restart")        \
  BOOL(sim_corrupt_tables, false, "boot with a damaged copy of the tables")                        \
  BOOL(sim_wait_for_client, false,                                                                 \
       "boot only once a socketcand client is in raw mode (to see the boot-up)")                   \
  BOOL(sim_print_truth, true, "RESULT/EMCY/STATE/MODELS lines on stdout")                          \
  TEXT(candump, kConfigPathMax, "", "candump-format log of every frame sent and received")
// clang-format on

// One identifier per key, in the order above (FwConfig::given has a bit for each).
#define STEREOHASH_FW_KEY_ID(name, ...) name,
enum class ConfigKeyId : uint8_t {
  STEREOHASH_FW_CONFIG_KEYS(STEREOHASH_FW_KEY_ID, STEREOHASH_FW_KEY_ID, STEREOHASH_FW_KEY_ID,
                            STEREOHASH_FW_KEY_ID, STEREOHASH_FW_KEY_ID, STEREOHASH_FW_KEY_ID,
                            STEREOHASH_FW_KEY_ID, STEREOHASH_FW_KEY_ID) kCount
};
#undef STEREOHASH_FW_KEY_ID

// A set of keys (those a file gave, those a text named): one bit per key, however many keys
// the list declares.
class ConfigKeySet {
 public:
  bool Has(size_t key) const { return (words_[key / 64] >> (key % 64)) & 1u; }
  void Add(size_t key) { words_[key / 64] |= uint64_t{1} << (key % 64); }

 private:
  uint64_t words_[(static_cast<size_t>(ConfigKeyId::kCount) + 63) / 64] = {};
};

struct FwConfig;

enum class KeyType : uint8_t { kInt, kIntOrOff, kMask, kCrc32, kBool, kChoice, kText, kVec3 };

// A row of the key table: where the field is and what it accepts.
struct ConfigKey {
  const char* name;
  KeyType type;
  size_t offset;        // of the FwConfig field
  size_t size;          // of the field in bytes
  bool is_signed;       // kInt, kIntOrOff
  long long min, max;   // kInt, kIntOrOff: the accepted range
  const char* choices;  // kChoice: names separated by '|'
  const char* unit;     // shown with the type ("ms", "mm", "0.1 Hz"), or ""
  const char* help;
};

// The blanks of a settings file around keys, values and list items: space, tab, and the carriage
// return of a file saved on Windows.
inline bool IsConfigBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// The keys in documentation order; index = ConfigKeyId.
const ConfigKey* ConfigKeys();
size_t ConfigKeyCount();
// The key called `name`, or nullptr.
const ConfigKey* FindConfigKey(const char* name);

// Parses `value` into the key's field of *config (and marks it given). The error says what
// was expected ("expected an integer in 1..127"); the caller adds the line and key.
Status ApplyConfigKey(const ConfigKey& key, const char* value, FwConfig* config);

// The key's value in `from` copied into *to, and marked given there as if *to's file gave it.
void CopyConfigKey(const ConfigKey& key, const FwConfig& from, FwConfig* to);

// The key's value in *config as it would be written in a file.
void FormatConfigValue(const ConfigKey& key, const FwConfig& config, char* out, size_t capacity);

// What the key accepts ("integer 1..127", "dark | light", "text, up to 15 characters").
void FormatConfigType(const ConfigKey& key, char* out, size_t capacity);

// `--help`: every key with what it accepts, its default in `defaults` and its help.
void PrintConfigKeys(std::FILE* out, const FwConfig& defaults);

// The Markdown table of docs/firmware.md: key, accepted values, board default, simulator default
// (when it differs), meaning.
void PrintConfigKeysMarkdown(std::FILE* out, const FwConfig& board_defaults,
                             const FwConfig& sim_defaults);

}  // namespace sh::fw
