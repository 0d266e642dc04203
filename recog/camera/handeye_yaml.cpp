#include "recog/camera/handeye_yaml.hpp"

#include "recog/camera/opencv_yaml.hpp"
#include "recog/camera/yaml_pose.hpp"

namespace sh {
namespace {

constexpr const char* kR = "R_robot_camera";
constexpr const char* kT = "t_robot_camera";

}  // namespace

Result<HandEye> ParseHandEyeYaml(const char* text, size_t length) {
  YamlInt eye_in_hand, poses;
  YamlMatrix R, t, residuals;
  YamlKey keys[] = {{"eye_in_hand", nullptr, &eye_in_hand, nullptr, nullptr},
                    {kR, nullptr, nullptr, &R, nullptr},
                    {kT, nullptr, nullptr, &t, nullptr},
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
  Eigen::Matrix3d R_d;
  Eigen::Vector3d t_d;
  SH_RETURN_IF_ERROR(PoseFromYaml(R, t, kR, kT, &R_d, &t_d));
  SH_RETURN_IF_ERROR(CheckPose(R_d, t_d, kR, kT, kMaxHandEyeDistanceMm, "a hand-eye pose"));
  HandEye h;
  h.eye_in_hand = eye_in_hand.value == 1;
  h.robot_T_camera = PoseTransform(R_d, t_d);
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
  SH_RETURN_IF_ERROR(CheckPose(h.robot_T_camera.R.cast<double>(),
                               h.robot_T_camera.t_mm.cast<double>(), kR, kT, kMaxHandEyeDistanceMm,
                               "a hand-eye pose"));
  if (out == nullptr || capacity == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "no output buffer");
  }
  const double residuals[4] = {h.residual_rms_mm, h.residual_max_mm, h.residual_rms_deg,
                               h.residual_max_deg};
  size_t used = 0;
  const bool fits = YamlAppend(out, capacity, &used, "%%YAML:1.0\n---\neye_in_hand: %d\n",
                               h.eye_in_hand ? 1 : 0) &&
                    YamlAppendPose(out, capacity, &used, kR, kT, h.robot_T_camera) &&
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
