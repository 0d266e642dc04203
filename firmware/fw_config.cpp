#include "firmware/fw_config.hpp"

#include <Eigen/Geometry>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#include "firmware/can_protocol.hpp"
#include "recog/base/printable.hpp"
#include "recog/pipeline/worker_pool.hpp"

namespace sh::fw {
namespace {

constexpr size_t kValueMax = kConfigPathMax;

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r'; }

Status LineError(int line, const char* key, const char* what, const char* value) {
  char shown_key[kPrintableNameBytes], shown_value[96];
  return Status::Error(StatusCode::kInvalidArgument, "line %d: key '%s': %s (got '%s')", line,
                       Printable(key, std::strlen(key), shown_key, sizeof(shown_key)), what,
                       Printable(value, std::strlen(value), shown_value, sizeof(shown_value)));
}

bool ParseInt(const char* text, long long min, long long max, long long* out) {
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(text, &end, 0);
  if (errno != 0 || end == text || *end != '\0' || v < min || v > max) return false;
  *out = v;
  return true;
}

// Exactly the two words the documentation and the message name.
bool ParseBool(const char* text, bool* out) {
  if (!std::strcmp(text, "true") || !std::strcmp(text, "false")) {
    *out = text[0] == 't';
    return true;
  }
  return false;
}

// Three numbers separated by spaces or commas.
bool ParseVec3(const char* text, float out[3]) {
  const char* p = text;
  for (int i = 0; i < 3; ++i) {
    while (IsSpace(*p) || *p == ',') ++p;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(p, &end);
    if (errno != 0 || end == p || !(v > -1e6 && v < 1e6)) return false;
    out[i] = static_cast<float>(v);
    p = end;
  }
  while (IsSpace(*p)) ++p;
  return *p == '\0';
}

bool CopyString(const char* value, char* out, size_t capacity) {
  const size_t n = std::strlen(value);
  if (n + 1 > capacity) return false;
  std::memcpy(out, value, n + 1);
  return true;
}

// Keys seen in this parse (repeated keys are an error: the later one would silently win).
struct SeenKeys {
  static constexpr size_t kMax = 64;
  char names[kMax][40] = {};
  size_t count = 0;
  bool Add(const char* key) {
    for (size_t i = 0; i < count; ++i) {
      if (!std::strcmp(names[i], key)) return false;
    }
    if (count < kMax) CopyString(key, names[count++], sizeof(names[0]));
    return true;
  }
};

Status ApplyKey(int line, const char* key, const char* value, FwConfig* c) {
  long long n = 0;
  bool b = false;
  auto is = [key](const char* name) { return std::strcmp(key, name) == 0; };
  auto int_key = [&](long long min, long long max, auto* field) -> Status {
    if (!ParseInt(value, min, max, &n)) {
      char what[96];
      std::snprintf(what, sizeof(what), "expected an integer in %lld..%lld", min, max);
      return LineError(line, key, what, value);
    }
    *field = static_cast<std::remove_pointer_t<decltype(field)>>(n);
    return Status::Ok();
  };
  auto bool_key = [&](bool* field) -> Status {
    if (!ParseBool(value, &b)) return LineError(line, key, "expected true or false", value);
    *field = b;
    return Status::Ok();
  };
  // A key with two named values: `when_false` or `when_true`.
  auto choice_key = [&](const char* when_false, const char* when_true, bool* field) -> Status {
    if (!std::strcmp(value, when_false)) {
      *field = false;
    } else if (!std::strcmp(value, when_true)) {
      *field = true;
    } else {
      char what[64];
      std::snprintf(what, sizeof(what), "expected %s or %s", when_false, when_true);
      return LineError(line, key, what, value);
    }
    return Status::Ok();
  };
  auto string_key = [&](char* field, size_t capacity) -> Status {
    if (!CopyString(value, field, capacity)) return LineError(line, key, "too long", value);
    return Status::Ok();
  };

  if (is("backend")) {
    if (!std::strcmp(value, "linux")) {
      c->backend = Backend::kLinux;
    } else if (!std::strcmp(value, "sim")) {
      c->backend = Backend::kSim;
    } else {
      return LineError(line, key, "expected linux or sim", value);
    }
    return Status::Ok();
  }
  if (is("can_interface")) return string_key(c->can_interface, sizeof(c->can_interface));
  if (is("node_id")) return int_key(protocol::kNodeIdMin, protocol::kNodeIdMax, &c->node_id);
  if (is("heartbeat_ms")) {
    // 0 switches the heartbeat off (CiA 301); below 10 ms it would flood the bus.
    if (!ParseInt(value, 0, 10000, &n) || (n > 0 && n < 10)) {
      return LineError(line, key, "expected 0 (off) or 10..10000", value);
    }
    c->heartbeat_ms = static_cast<uint32_t>(n);
    return Status::Ok();
  }
  if (is("result_mode")) {
    const char* names[] = {"stream", "pdo", "both"};
    for (uint8_t m = 0; m < 3; ++m) {
      if (!std::strcmp(value, names[m])) {
        c->result_mode = m;
        return Status::Ok();
      }
    }
    return LineError(line, key, "expected stream, pdo or both", value);
  }
  if (is("serial_number")) return int_key(0, 0xFFFFFFFFll, &c->serial_number);
  if (is("lss_store")) {
    c->lss_store_set = true;
    return string_key(c->lss_store_path, sizeof(c->lss_store_path));
  }
  if (is("camera")) {
    if (!std::strcmp(value, "directory")) {
      c->camera = CameraSource::kDirectory;
    } else if (!std::strcmp(value, "libcamera") || !std::strcmp(value, "sim")) {
      c->camera = CameraSource::kBackend;
    } else {
      return LineError(line, key, "expected libcamera, sim or directory", value);
    }
    return Status::Ok();
  }
  if (is("camera_directory")) return string_key(c->camera_directory, sizeof(c->camera_directory));
  if (is("table_file")) return string_key(c->table_file, sizeof(c->table_file));
  if (is("output_frame")) {
    if (!std::strcmp(value, "camera")) {
      c->output_frame = OutputFrameKey::kCamera;
    } else if (!std::strcmp(value, "table")) {
      c->output_frame = OutputFrameKey::kTable;
    } else if (!std::strcmp(value, "robot")) {
      c->output_frame = OutputFrameKey::kRobot;
    } else {
      return LineError(line, key, "expected camera, table or robot", value);
    }
    return Status::Ok();
  }
  if (is("handeye")) return string_key(c->handeye_path, sizeof(c->handeye_path));
  if (is("record_dir")) return string_key(c->record_dir, sizeof(c->record_dir));
  if (is("record_max")) return int_key(1, kMaxRecordPairs, &c->record_max);
  if (is("record_format")) return choice_key("png", "pgm", &c->record_pgm);
  if (is("camera_left_id")) return string_key(c->camera_left_id, sizeof(c->camera_left_id));
  if (is("camera_right_id")) return string_key(c->camera_right_id, sizeof(c->camera_right_id));
  if (is("camera_left_index")) return int_key(0, 15, &c->camera_left_index);
  if (is("camera_right_index")) return int_key(0, 15, &c->camera_right_index);
  if (is("camera_width")) return int_key(16, 1280, &c->camera_width);    // kMaxImageWidth
  if (is("camera_height")) return int_key(16, 1024, &c->camera_height);  // kMaxImageHeight
  if (is("capture_timeout_ms")) return int_key(10, 60000, &c->capture_timeout_ms);
  if (is("calibration")) return string_key(c->calibration_path, sizeof(c->calibration_path));
  if (is("tables")) return string_key(c->tables_path, sizeof(c->tables_path));
  if (is("models_dir")) return string_key(c->models_dir, sizeof(c->models_dir));
  if (is("recognition")) {
    if (!std::strcmp(value, "pipeline")) {
      c->recognition = RecognitionKind::kPipeline;
    } else if (!std::strcmp(value, "truth")) {
      c->recognition = RecognitionKind::kTruth;
    } else {
      return LineError(line, key, "expected pipeline or truth", value);
    }
    return Status::Ok();
  }
  if (is("budget_ms")) {
    return int_key(protocol::kTimeBudgetMinMs, protocol::kTimeBudgetMaxMs, &c->budget_ms);
  }
  if (is("free_run_dhz")) return int_key(0, protocol::kFreeRunRateMaxDeciHz, &c->free_run_dhz);
  if (is("model_mask")) {
    if (!ParseInt(value, 1, 0xFFFFFFFFll, &n)) {
      return LineError(line, key, "expected a non-zero 32-bit mask", value);
    }
    c->model_mask = static_cast<uint32_t>(n);
    return Status::Ok();
  }
  if (is("volume_min_mm") || is("volume_max_mm")) {
    float v[3];
    if (!ParseVec3(value, v)) return LineError(line, key, "expected three numbers (mm)", value);
    std::memcpy(is("volume_min_mm") ? c->volume_min_mm : c->volume_max_mm, v, sizeof(v));
    c->volume_set = true;
    c->volume_is_sim_default = false;
    return Status::Ok();
  }
  if (is("volume_frame")) return choice_key("camera", "table", &c->volume_in_table_frame);
  if (is("table_rotation_deg") || is("table_origin_mm")) {
    float v[3];
    if (!ParseVec3(value, v)) return LineError(line, key, "expected three numbers", value);
    std::memcpy(is("table_rotation_deg") ? c->table_rotation_deg : c->table_origin_mm, v,
                sizeof(v));
    c->table_pose_set = true;
    return Status::Ok();
  }
  if (is("background")) {
    if (std::strcmp(value, "auto") == 0) {
      c->background_set = false;  // thresholds measured from each image
      return Status::Ok();
    }
    c->background_set = true;
    return choice_key("dark", "light", &c->light_background);
  }
  if (is("threads")) return int_key(0, kMaxPoolThreads, &c->threads);
  if (is("gpio_chip")) return string_key(c->gpio_chip, sizeof(c->gpio_chip));
  if (is("gpio_trigger_line")) return int_key(-1, 1023, &c->gpio_trigger_line);
  if (is("gpio_ready_line")) return int_key(-1, 1023, &c->gpio_ready_line);
  if (is("gpio_busy_line")) return int_key(-1, 1023, &c->gpio_busy_line);
  if (is("gpio_strobe_line")) return int_key(-1, 1023, &c->gpio_strobe_line);
  if (is("gpio_outputs_active_low")) return bool_key(&c->gpio_outputs_active_low);
  if (is("gpio_trigger_active_low")) return bool_key(&c->gpio_trigger_active_low);
  if (is("mlock")) return bool_key(&c->mlock);
  if (is("sched_fifo_priority")) return int_key(0, 99, &c->sched_fifo_priority);
  if (is("sim_port")) return int_key(0, 65535, &c->sim_port);
  // hal::kSocketcandMaxClients (fw_main.cpp asserts the two agree).
  if (is("sim_socketcand_clients")) return int_key(1, 16, &c->sim_socketcand_clients);
  if (is("sim_socketcand_handshake_ms")) return int_key(1, 600000, &c->sim_socketcand_handshake_ms);
  if (is("sim_socketcand_idle_ms")) return int_key(0, 600000, &c->sim_socketcand_idle_ms);
  if (is("sim_socketcand_stall_ms")) return int_key(1, 600000, &c->sim_socketcand_stall_ms);
  if (is("sim_seed")) {
    if (!ParseInt(value, 0, 0x7FFFFFFFFFFFFFFFll, &n)) {
      return LineError(line, key, "expected a non-negative integer", value);
    }
    c->sim_seed = static_cast<uint64_t>(n);
    return Status::Ok();
  }
  if (is("sim_background")) return choice_key("dark", "light", &c->sim_light_background);
  if (is("sim_objects")) return int_key(1, 16, &c->sim_objects);  // kMaxRenderObjects
  if (is("sim_scenes")) return int_key(1, 64, &c->sim_scenes);
  if (is("sim_camera_fault")) {
    if (!std::strcmp(value, "none")) {
      c->sim_camera_fault = SimCameraFault::kNone;
    } else if (!std::strcmp(value, "right_silent")) {
      c->sim_camera_fault = SimCameraFault::kRightSilent;
    } else if (!std::strcmp(value, "drop_right")) {
      c->sim_camera_fault = SimCameraFault::kDropRight;
    } else {
      return LineError(line, key, "expected none, right_silent or drop_right", value);
    }
    return Status::Ok();
  }
  if (is("sim_corrupt_tables")) return bool_key(&c->sim_corrupt_tables);
  if (is("sim_wait_for_client")) return bool_key(&c->sim_wait_for_client);
  if (is("sim_print_truth")) return bool_key(&c->sim_print_truth);
  if (is("candump")) return string_key(c->candump_path, sizeof(c->candump_path));
  char shown[kPrintableNameBytes];
  return Status::Error(StatusCode::kInvalidArgument, "line %d: unknown key '%s'", line,
                       Printable(key, std::strlen(key), shown, sizeof(shown)));
}

}  // namespace

Status ParseConfig(const char* text, size_t length, FwConfig* config) {
  SeenKeys seen;
  size_t pos = 0;
  // A UTF-8 byte-order mark, as some Windows editors write, is not part of the first key.
  if (length >= 3 && std::memcmp(text, "\xEF\xBB\xBF", 3) == 0) pos = 3;
  int line = 0;
  while (pos < length) {
    ++line;
    size_t end = pos;
    while (end < length && text[end] != '\n') ++end;
    // Copy the line without comment, trimmed.
    char buf[kValueMax + 64];
    size_t n = 0;
    bool too_long = false;
    for (size_t i = pos; i < end && text[i] != '#'; ++i) {
      if (text[i] == '\0') {
        return Status::Error(StatusCode::kInvalidArgument, "line %d: NUL byte in the text", line);
      }
      if (n + 1 >= sizeof(buf)) {
        too_long = true;
        break;
      }
      buf[n++] = text[i];
    }
    pos = end + 1;
    if (too_long) {
      return Status::Error(StatusCode::kInvalidArgument, "line %d: longer than %zu characters",
                           line, sizeof(buf) - 1);
    }
    while (n > 0 && IsSpace(buf[n - 1])) --n;
    buf[n] = '\0';
    char* p = buf;
    while (IsSpace(*p)) ++p;
    if (*p == '\0') continue;
    char* eq = std::strchr(p, '=');
    if (eq == nullptr) {
      char shown[96];
      return Status::Error(StatusCode::kInvalidArgument,
                           "line %d: expected 'key = value', got '%s'", line,
                           Printable(p, std::strlen(p), shown, sizeof(shown)));
    }
    char* key_end = eq;
    while (key_end > p && IsSpace(key_end[-1])) --key_end;
    *key_end = '\0';
    char* value = eq + 1;
    while (IsSpace(*value)) ++value;
    if (*p == '\0') {
      return Status::Error(StatusCode::kInvalidArgument, "line %d: missing key before '='", line);
    }
    if (*value == '\0') return LineError(line, p, "missing value", "");
    if (!seen.Add(p)) {
      char shown[kPrintableNameBytes];
      return Status::Error(StatusCode::kInvalidArgument, "line %d: key '%s' given twice", line,
                           Printable(p, std::strlen(p), shown, sizeof(shown)));
    }
    SH_RETURN_IF_ERROR(ApplyKey(line, p, value, config));
  }
  return Status::Ok();
}

RigidTransform TablePose(const FwConfig& c) {
  const Eigen::Vector3f r_rad =
      Eigen::Vector3f(c.table_rotation_deg[0], c.table_rotation_deg[1], c.table_rotation_deg[2]) *
      float(M_PI / 180.0);
  const float angle = r_rad.norm();
  RigidTransform t;
  t.R = angle > 0.0f ? Eigen::AngleAxisf(angle, r_rad / angle).toRotationMatrix()
                     : Eigen::Matrix3f::Identity();
  t.t_mm = Eigen::Vector3f(c.table_origin_mm[0], c.table_origin_mm[1], c.table_origin_mm[2]);
  return t;
}

Status ValidateConfig(const FwConfig& c) {
  if (c.backend == Backend::kLinux) {
    if (c.calibration_path[0] == '\0') {
      return Status::Error(StatusCode::kInvalidArgument,
                           "key 'calibration': required with backend = linux");
    }
    if (c.recognition == RecognitionKind::kTruth) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "key 'recognition': 'truth' exists only with backend = sim");
    }
  }
  if (c.camera_left_index == c.camera_right_index && c.camera_left_id[0] == '\0') {
    return Status::Error(StatusCode::kInvalidArgument,
                         "keys 'camera_left_index'/'camera_right_index': both are %d",
                         c.camera_left_index);
  }
  if (c.table_file[0] != '\0' && c.table_pose_set) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'table_file' and 'table_rotation_deg'/'table_origin_mm' both give "
                         "the table pose: keep one");
  }
  const bool table_known = c.table_pose_set || c.table_file[0] != '\0';
  if (c.output_frame == OutputFrameKey::kTable && !table_known && c.backend != Backend::kSim) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'output_frame = table' needs the table pose: 'table_file' or "
                         "'table_rotation_deg' and 'table_origin_mm'");
  }
  if (c.output_frame == OutputFrameKey::kRobot && c.handeye_path[0] == '\0') {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'output_frame = robot' needs 'handeye', the file written by "
                         "stereohash calibrate-handeye");
  }
  if (c.camera == CameraSource::kDirectory && c.camera_directory[0] == '\0') {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'camera = directory' needs 'camera_directory'");
  }
  if (c.volume_in_table_frame && !table_known && c.backend != Backend::kSim) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'volume_frame = table' needs the table pose: 'table_rotation_deg' "
                         "and 'table_origin_mm'");
  }
  for (int i = 0; i < 3; ++i) {
    if (!(c.volume_min_mm[i] < c.volume_max_mm[i])) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "keys 'volume_min_mm'/'volume_max_mm': min must be below max on "
                           "axis %d",
                           i);
    }
  }
  return Status::Ok();
}

Status LoadConfigFile(const char* path, FwConfig* config) {
  static char text[kMaxConfigFileBytes];
  std::FILE* f = std::fopen(path, "rb");
  if (f == nullptr) {
    return Status::Error(StatusCode::kNotFound, "cannot open config %s: %s", path,
                         std::strerror(errno));
  }
  const size_t n = std::fread(text, 1, sizeof(text), f);
  const bool more = std::fgetc(f) != EOF;
  const bool error = std::ferror(f) != 0;
  std::fclose(f);
  if (error) return Status::Error(StatusCode::kUnavailable, "cannot read config %s", path);
  if (more) {
    return Status::Error(StatusCode::kOutOfRange, "config %s is larger than %zu bytes", path,
                         kMaxConfigFileBytes);
  }
  const Status parsed = ParseConfig(text, n, config);
  if (!parsed.ok()) {
    return Status::Error(parsed.code(), "%s: %s", path, parsed.message());
  }
  return ValidateConfig(*config);
}

}  // namespace sh::fw
