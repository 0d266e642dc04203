#include "recog/camera/handeye_yaml.hpp"

#include <cmath>

#include "recog/camera/calibration_check.hpp"
#include "recog/camera/opencv_yaml.hpp"

namespace sh {
namespace {

Status CheckHandEye(const Eigen::Matrix3d& R, const Eigen::Vector3d& t_mm) {
  SH_RETURN_IF_ERROR(ValidateRotation(R, "R_robot_camera"));
  if (!t_mm.allFinite()) {
    return Status::Error(StatusCode::kInvalidArgument, "t_robot_camera is not finite");
  }
  if (t_mm.norm() > kMaxHandEyeDistanceMm) {
    return Status::Error(StatusCode::kOutOfRange,
                         "t_robot_camera puts the camera %.0f mm from the robot frame, more than "
                         "%.0f mm: not a hand-eye pose in millimetres",
                         t_mm.norm(), kMaxHandEyeDistanceMm);
  }
  return Status::Ok();
}

}  // namespace

Result<HandEye> ParseHandEyeYaml(const char* text, size_t length) {
  YamlInt eye_in_hand, poses;
  YamlMatrix R, t, residuals;
  YamlKey keys[] = {{"eye_in_hand", nullptr, &eye_in_hand, nullptr, nullptr},
                    {"R_robot_camera", nullptr, nullptr, &R, nullptr},
                    {"t_robot_camera", nullptr, nullptr, &t, nullptr},
                    {"poses", nullptr, &poses, nullptr, nullptr},
                    {"residuals_mm_deg", nullptr, nullptr, &residuals, nullptr}};
  SH_RETURN_IF_ERROR(ReadOpenCvYaml(text, length, kMaxHandEyeYamlBytes, "hand-eye file", keys, 5));
  if (!eye_in_hand.present) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "missing key 'eye_in_hand' (0: cameras fixed, 1: cameras on the robot)");
  }
  if (eye_in_hand.value != 0 && eye_in_hand.value != 1) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "line %d: eye_in_hand must be 0 or 1, got %d", eye_in_hand.line,
                         eye_in_hand.value);
  }
  if (!R.present)
    return Status::Error(StatusCode::kInvalidArgument, "missing key 'R_robot_camera'");
  if (!t.present)
    return Status::Error(StatusCode::kInvalidArgument, "missing key 't_robot_camera'");
  if (R.rows != 3 || R.cols != 3) {
    return Status::Error(StatusCode::kInvalidArgument, "R_robot_camera must be 3x3, got %dx%d",
                         R.rows, R.cols);
  }
  if (t.count != 3 || (t.rows != 1 && t.cols != 1)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "t_robot_camera must be 3x1 or 1x3, got %dx%d", t.rows, t.cols);
  }
  Eigen::Matrix3d R_d;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R_d(r, c) = R.data[r * 3 + c];  // row-major data
  }
  const Eigen::Vector3d t_d(t.data[0], t.data[1], t.data[2]);
  SH_RETURN_IF_ERROR(CheckHandEye(R_d, t_d));
  HandEye h;
  h.eye_in_hand = eye_in_hand.value == 1;
  h.robot_T_camera.R = NearestRotation(R_d).cast<float>();
  h.robot_T_camera.t_mm = t_d.cast<float>();
  h.poses = poses.present ? poses.value : 0;
  if (residuals.present && residuals.count == 4) {
    h.residual_rms_mm = residuals.data[0];
    h.residual_max_mm = residuals.data[1];
    h.residual_rms_deg = residuals.data[2];
    h.residual_max_deg = residuals.data[3];
  }
  return h;
}

Result<size_t> WriteHandEyeYaml(const HandEye& h, char* out, size_t capacity) {
  const Eigen::Matrix3d R_d = h.robot_T_camera.R.cast<double>();
  const Eigen::Vector3d t_d = h.robot_T_camera.t_mm.cast<double>();
  SH_RETURN_IF_ERROR(CheckHandEye(R_d, t_d));
  if (out == nullptr || capacity == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "no output buffer");
  }
  double R[9];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R[r * 3 + c] = R_d(r, c);
  }
  const double t[3] = {t_d.x(), t_d.y(), t_d.z()};
  const double residuals[4] = {h.residual_rms_mm, h.residual_max_mm, h.residual_rms_deg,
                               h.residual_max_deg};
  size_t used = 0;
  const bool fits = YamlAppend(out, capacity, &used, "%%YAML:1.0\n---\neye_in_hand: %d\n",
                               h.eye_in_hand ? 1 : 0) &&
                    YamlAppendMatrix(out, capacity, &used, "R_robot_camera", 3, 3, R) &&
                    YamlAppendMatrix(out, capacity, &used, "t_robot_camera", 3, 1, t) &&
                    YamlAppend(out, capacity, &used, "poses: %d\n", h.poses) &&
                    YamlAppendMatrix(out, capacity, &used, "residuals_mm_deg", 1, 4, residuals);
  if (!fits) {
    out[0] = '\0';
    return Status::Error(StatusCode::kResourceExhausted,
                         "hand-eye YAML does not fit the %zu-byte output buffer", capacity);
  }
  return used;
}

}  // namespace sh
