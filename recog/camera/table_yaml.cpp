#include "recog/camera/table_yaml.hpp"

#include <cmath>

#include "recog/camera/calibration_check.hpp"
#include "recog/camera/opencv_yaml.hpp"

namespace sh {
namespace {

// Checks the pose in double precision, before it is narrowed to the float transform.
Status CheckTablePose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t_mm) {
  SH_RETURN_IF_ERROR(ValidateRotation(R, "R_table"));
  if (!t_mm.allFinite()) {
    return Status::Error(StatusCode::kInvalidArgument, "t_table is not finite");
  }
  if (t_mm.norm() > kMaxTableDistanceMm) {
    return Status::Error(StatusCode::kOutOfRange,
                         "t_table puts the table %.0f mm from the camera, more than %.0f mm: "
                         "not a table pose in millimetres",
                         t_mm.norm(), kMaxTableDistanceMm);
  }
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
  if (!R.present) return Status::Error(StatusCode::kInvalidArgument, "missing key 'R_table'");
  if (!t.present) return Status::Error(StatusCode::kInvalidArgument, "missing key 't_table'");
  if (R.rows != 3 || R.cols != 3) {
    return Status::Error(StatusCode::kInvalidArgument, "R_table must be 3x3, got %dx%d", R.rows,
                         R.cols);
  }
  if (t.count != 3 || (t.rows != 1 && t.cols != 1)) {
    return Status::Error(StatusCode::kInvalidArgument, "t_table must be 3x1 or 1x3, got %dx%d",
                         t.rows, t.cols);
  }
  Eigen::Matrix3d R_d;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R_d(r, c) = R.data[r * 3 + c];  // row-major data
  }
  const Eigen::Vector3d t_d(t.data[0], t.data[1], t.data[2]);
  SH_RETURN_IF_ERROR(CheckTablePose(R_d, t_d));
  RigidTransform left_T_table;
  left_T_table.R = NearestRotation(R_d).cast<float>();
  left_T_table.t_mm = t_d.cast<float>();
  return left_T_table;
}

Result<size_t> WriteTableYaml(const RigidTransform& left_T_table, char* out, size_t capacity) {
  const Eigen::Matrix3d R_d = left_T_table.R.cast<double>();
  const Eigen::Vector3d t_d = left_T_table.t_mm.cast<double>();
  SH_RETURN_IF_ERROR(CheckTablePose(R_d, t_d));
  if (out == nullptr || capacity == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "no output buffer");
  }
  double R[9];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R[r * 3 + c] = R_d(r, c);
  }
  const double t[3] = {t_d.x(), t_d.y(), t_d.z()};
  size_t used = 0;
  const bool fits = YamlAppend(out, capacity, &used, "%%YAML:1.0\n---\n") &&
                    YamlAppendMatrix(out, capacity, &used, "R_table", 3, 3, R) &&
                    YamlAppendMatrix(out, capacity, &used, "t_table", 3, 1, t);
  if (!fits) {
    out[0] = '\0';
    return Status::Error(StatusCode::kResourceExhausted,
                         "table YAML does not fit the %zu-byte output buffer", capacity);
  }
  return used;
}

}  // namespace sh
