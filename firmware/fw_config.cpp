#include "firmware/fw_config.hpp"

#include <Eigen/Geometry>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "firmware/config_keys.hpp"
#include "recog/base/printable.hpp"
#include "tables/input_file.hpp"

namespace sh::fw {
namespace {

Status LineError(int line, const char* key, const char* what, const char* value) {
  char shown_key[kPrintableNameBytes], shown_value[96];
  return Status::Error(StatusCode::kInvalidArgument, "line %d: key '%s': %s (got '%s')", line,
                       Printable(key, std::strlen(key), shown_key, sizeof(shown_key)), what,
                       Printable(value, std::strlen(value), shown_value, sizeof(shown_value)));
}

}  // namespace

Status ParseConfig(const char* text, size_t length, FwConfig* config) {
  ConfigKeySet seen;  // keys of this text: a repeated key is an error (the later would win)
  size_t pos = 0;
  // A UTF-8 byte-order mark, as some Windows editors write, is not part of the first key.
  if (length >= 3 && std::memcmp(text, "\xEF\xBB\xBF", 3) == 0) pos = 3;
  int line = 0;
  while (pos < length) {
    ++line;
    size_t end = pos;
    while (end < length && text[end] != '\n') ++end;
    // Copy the line without comment, trimmed.
    char buf[kConfigPathMax + 64];
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
    while (n > 0 && IsConfigBlank(buf[n - 1])) --n;
    buf[n] = '\0';
    char* p = buf;
    while (IsConfigBlank(*p)) ++p;
    if (*p == '\0') continue;
    char* eq = std::strchr(p, '=');
    if (eq == nullptr) {
      char shown[96];
      return Status::Error(StatusCode::kInvalidArgument,
                           "line %d: expected 'key = value', got '%s'", line,
                           Printable(p, std::strlen(p), shown, sizeof(shown)));
    }
    char* key_end = eq;
    while (key_end > p && IsConfigBlank(key_end[-1])) --key_end;
    *key_end = '\0';
    char* value = eq + 1;
    while (IsConfigBlank(*value)) ++value;
    if (*p == '\0') {
      return Status::Error(StatusCode::kInvalidArgument, "line %d: missing key before '='", line);
    }
    const ConfigKey* key = FindConfigKey(p);
    if (key == nullptr) {
      char shown[kPrintableNameBytes];
      return Status::Error(StatusCode::kInvalidArgument, "line %d: unknown key '%s'", line,
                           Printable(p, std::strlen(p), shown, sizeof(shown)));
    }
    if (*value == '\0') return LineError(line, p, "missing value", "");
    const size_t index = static_cast<size_t>(key - ConfigKeys());
    if (seen.Has(index)) {
      return Status::Error(StatusCode::kInvalidArgument, "line %d: key '%s' given twice", line, p);
    }
    seen.Add(index);
    const Status applied = ApplyConfigKey(*key, value, config);
    if (!applied.ok()) return LineError(line, p, applied.message(), value);
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
    if (c.calibration[0] == '\0') {
      return Status::Error(StatusCode::kInvalidArgument,
                           "key 'calibration': required with backend = linux");
    }
    if (c.recognition == RecognitionKind::kTruth) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "key 'recognition': 'truth' exists only with backend = sim");
    }
    if (c.camera != CameraSource::kLibcamera) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "key 'camera': the board's cameras are libcamera; recorded pairs "
                           "(directory) are replayed by stereohash-fw-sim");
    }
  } else if (c.camera == CameraSource::kLibcamera) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'camera': the simulator has the simulated world's cameras (sim) "
                         "or recorded pairs (directory), not libcamera");
  }
  if (c.camera_left_index == c.camera_right_index && c.camera_left_id[0] == '\0') {
    return Status::Error(StatusCode::kInvalidArgument,
                         "keys 'camera_left_index'/'camera_right_index': both are %d",
                         c.camera_left_index);
  }
  if (c.table_file[0] != '\0' && c.table_pose_set()) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'table_file' and 'table_rotation_deg'/'table_origin_mm' both give "
                         "the table pose: keep one");
  }
  const bool table_known = c.table_pose_set() || c.table_file[0] != '\0';
  if (c.output_frame == OutputFrameKey::kTable && !table_known && c.backend != Backend::kSim) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'output_frame = table' needs the table pose: 'table_file' or "
                         "'table_rotation_deg' and 'table_origin_mm'");
  }
  if (c.output_frame == OutputFrameKey::kRobot && c.handeye[0] == '\0') {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'output_frame = robot' needs 'handeye', the file written by "
                         "stereohash calibrate-handeye");
  }
  if (c.camera == CameraSource::kDirectory && c.camera_directory[0] == '\0') {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'camera = directory' needs 'camera_directory'");
  }
  if (c.camera == CameraSource::kDirectory && c.recognition == RecognitionKind::kTruth) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'recognition = truth' needs the rendered scenes, not camera = "
                         "directory");
  }
  if (c.volume_frame == VolumeFrame::kTable && !table_known && c.backend != Backend::kSim) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "key 'volume_frame = table' needs the table pose: 'table_rotation_deg' "
                         "and 'table_origin_mm'");
  }
  if (c.http_password[0] != '\0' && c.http_password_file[0] != '\0') {
    return Status::Error(StatusCode::kInvalidArgument,
                         "keys 'http_password' and 'http_password_file' both give the web "
                         "password: keep one");
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
  size_t n = 0;
  SH_RETURN_IF_ERROR(ReadInputFile(path, "config", text, sizeof(text), &n));
  SH_RETURN_IF_ERROR(ParseConfig(text, n, config).WithContext("%s", path));
  return ValidateConfig(*config);
}

}  // namespace sh::fw
