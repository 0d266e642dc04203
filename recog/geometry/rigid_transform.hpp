// Rigid transforms named by the frames they connect: `a_T_b` maps coordinates in frame b into
// frame a, so `cam_T_model * x_model` is a model point in camera coordinates (millimetres).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sh {

struct RigidTransform {
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t_mm = Eigen::Vector3f::Zero();

  static RigidTransform Identity() { return {}; }
  Eigen::Vector3f operator*(const Eigen::Vector3f& x) const { return R * x + t_mm; }
  Eigen::Vector3f Rotate(const Eigen::Vector3f& v) const { return R * v; }
  RigidTransform operator*(const RigidTransform& other) const {
    return {R * other.R, R * other.t_mm + t_mm};
  }
  RigidTransform Inverse() const {
    const Eigen::Matrix3f Rt = R.transpose();
    return {Rt, -(Rt * t_mm)};
  }
};

// Re-orthonormalises R (accumulated float error) through its polar decomposition.
inline void Orthonormalize(RigidTransform& T) {
  const Eigen::Quaternionf q(T.R);
  T.R = q.normalized().toRotationMatrix();
}

// Rotation angle of R in degrees, in [0, 180].
inline float RotationAngleDeg(const Eigen::Matrix3f& R) {
  const float c = std::max(-1.0f, std::min(1.0f, (R.trace() - 1.0f) * 0.5f));
  return std::acos(c) * 57.29577951f;
}

}  // namespace sh
