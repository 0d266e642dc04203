#include "recog/stereo/working_volume.hpp"

#include <algorithm>
#include <cmath>

namespace sh {

WorkingVolume WorkingVolume::InLeftCamera(const Eigen::Vector3f& min_mm,
                                          const Eigen::Vector3f& max_mm) {
  return InFrame(RigidTransform::Identity(), min_mm, max_mm);
}

WorkingVolume WorkingVolume::InFrame(const RigidTransform& left_T_table,
                                     const Eigen::Vector3f& min_mm, const Eigen::Vector3f& max_mm) {
  WorkingVolume v;
  v.left_T_box = left_T_table;
  v.min_mm = min_mm.cwiseMin(max_mm);
  v.max_mm = min_mm.cwiseMax(max_mm);
  return v;
}

WorkingVolume WorkingVolume::OverTable(const RigidTransform& left_T_table) {
  return InFrame(
      left_T_table,
      Eigen::Vector3f(-kTableVolumeHalfWidthMm, -kTableVolumeHalfWidthMm, -kTableVolumeBelowMm),
      Eigen::Vector3f(kTableVolumeHalfWidthMm, kTableVolumeHalfWidthMm, kTableVolumeHeightMm));
}

namespace {
// Box frame from left frame, in double: x_box = R^T (x_left - t).
Eigen::Vector3d ToBox(const RigidTransform& left_T_box, const Eigen::Vector3d& p_left) {
  return left_T_box.R.cast<double>().transpose() * (p_left - left_T_box.t_mm.cast<double>());
}
}  // namespace

bool WorkingVolume::Contains(const Eigen::Vector3d& p_left_mm) const {
  const Eigen::Vector3d p = ToBox(left_T_box, p_left_mm);
  return (p.array() >= min_mm.cast<double>().array()).all() &&
         (p.array() <= max_mm.cast<double>().array()).all();
}

bool WorkingVolume::Clip(const Line3& line_left, double* s0_mm, double* s1_mm) const {
  // Slab method in the box frame; the parameter s is the same in both frames (rigid motion).
  const Eigen::Vector3d p = ToBox(left_T_box, line_left.point_mm);
  const Eigen::Vector3d d = left_T_box.R.cast<double>().transpose() * line_left.direction;
  double lo = -1e300, hi = 1e300;
  for (int axis = 0; axis < 3; ++axis) {
    const double min_v = min_mm(axis), max_v = max_mm(axis);
    if (std::fabs(d(axis)) < 1e-12) {
      if (p(axis) < min_v || p(axis) > max_v) return false;
      continue;
    }
    double t0 = (min_v - p(axis)) / d(axis);
    double t1 = (max_v - p(axis)) / d(axis);
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
  }
  if (!(lo <= hi)) return false;
  *s0_mm = lo;
  *s1_mm = hi;
  return true;
}

}  // namespace sh
