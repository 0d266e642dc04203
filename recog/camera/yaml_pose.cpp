#include "recog/camera/yaml_pose.hpp"

#include "recog/camera/calibration_check.hpp"

namespace sh {

Status PoseFromYaml(const YamlMatrix& R, const YamlMatrix& t, const char* r_name,
                    const char* t_name, Eigen::Matrix3d* R_out, Eigen::Vector3d* t_out) {
  if (!R.present) return Status::Error(StatusCode::kInvalidArgument, "missing key '%s'", r_name);
  if (!t.present) return Status::Error(StatusCode::kInvalidArgument, "missing key '%s'", t_name);
  if (R.rows != 3 || R.cols != 3) {
    return Status::Error(StatusCode::kInvalidArgument, "%s must be 3x3, got %dx%d", r_name, R.rows,
                         R.cols);
  }
  if (t.count != 3 || (t.rows != 1 && t.cols != 1)) {
    return Status::Error(StatusCode::kInvalidArgument, "%s must be 3x1 or 1x3, got %dx%d", t_name,
                         t.rows, t.cols);
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) (*R_out)(r, c) = R.data[r * 3 + c];  // row-major data
  }
  *t_out = Eigen::Vector3d(t.data[0], t.data[1], t.data[2]);
  return Status::Ok();
}

Status CheckPose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t_mm, const char* r_name,
                 const char* t_name, double max_distance_mm, const char* what) {
  SH_RETURN_IF_ERROR(ValidateRotation(R, r_name));
  if (!t_mm.allFinite()) {
    return Status::Error(StatusCode::kInvalidArgument, "%s is not finite", t_name);
  }
  if (t_mm.norm() > max_distance_mm) {
    return Status::Error(StatusCode::kOutOfRange,
                         "%s is %.0f mm from the origin, more than %.0f mm: not %s in millimetres",
                         t_name, t_mm.norm(), max_distance_mm, what);
  }
  return Status::Ok();
}

RigidTransform PoseTransform(const Eigen::Matrix3d& R, const Eigen::Vector3d& t_mm) {
  RigidTransform T;
  T.R = NearestRotation(R).cast<float>();
  T.t_mm = t_mm.cast<float>();
  return T;
}

bool YamlAppendPose(char* out, size_t capacity, size_t* used, const char* r_name,
                    const char* t_name, const RigidTransform& pose) {
  double R[9];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R[r * 3 + c] = pose.R(r, c);
  }
  const double t[3] = {pose.t_mm.x(), pose.t_mm.y(), pose.t_mm.z()};
  return YamlAppendMatrix(out, capacity, used, r_name, 3, 3, R) &&
         YamlAppendMatrix(out, capacity, used, t_name, 3, 1, t);
}

}  // namespace sh
