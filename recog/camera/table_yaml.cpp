#include "recog/camera/table_yaml.hpp"

#include <cmath>

#include "recog/camera/opencv_yaml.hpp"
#include "recog/camera/yaml_pose.hpp"

namespace sh {
namespace {

// Checks the pose in double precision, before it is narrowed to the float transform.
Status CheckTablePose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t_mm) {
  SH_RETURN_IF_ERROR(CheckPose(R, t_mm, "R_table", "t_table", kMaxTableDistanceMm, "a table pose"));
  // The table's z axis points up, towards the cameras that look down on it: in the left camera
  // frame the table normal R e_z must point back along the viewing ray to the table origin.
  const Eigen::Vector3d normal_left = R.col(2);
  if (t_mm.norm() > 0 && normal_left.dot(t_mm) >= 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "R_table's z axis points away from the camera: the table frame must "
                         "have z up, towards the cameras (is an axis flipped?)");
  }
  return Status::Ok();
}

}  // namespace

Result<RigidTransform> ParseTableYaml(const char* text, size_t length) {
  YamlMatrix R, t;
  YamlKey keys[] = {{"R_table", nullptr, nullptr, &R, nullptr},
                    {"t_table", nullptr, nullptr, &t, nullptr}};
  SH_RETURN_IF_ERROR(ReadOpenCvYaml(text, length, kMaxTableYamlBytes, "table file", keys, 2));
  Eigen::Matrix3d R_d;
  Eigen::Vector3d t_d;
  SH_RETURN_IF_ERROR(PoseFromYaml(R, t, "R_table", "t_table", &R_d, &t_d));
  SH_RETURN_IF_ERROR(CheckTablePose(R_d, t_d));
  return PoseTransform(R_d, t_d);
}

Result<size_t> WriteTableYaml(const RigidTransform& left_T_table, char* out, size_t capacity) {
  const Eigen::Matrix3d R_d = left_T_table.R.cast<double>();
  const Eigen::Vector3d t_d = left_T_table.t_mm.cast<double>();
  SH_RETURN_IF_ERROR(CheckTablePose(R_d, t_d));
  if (out == nullptr || capacity == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "no output buffer");
  }
  size_t used = 0;
  const bool fits = YamlAppend(out, capacity, &used, "%%YAML:1.0\n---\n") &&
                    YamlAppendPose(out, capacity, &used, "R_table", "t_table", left_T_table);
  if (!fits) {
    out[0] = '\0';
    return Status::Error(StatusCode::kResourceExhausted,
                         "table YAML does not fit the %zu-byte output buffer", capacity);
  }
  return used;
}

}  // namespace sh
