#include "recog/stereo/epipolar.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace sh {

Eigen::Matrix3d EssentialMatrix(const StereoCalibration& calib) {
  const Eigen::Vector3d& t = calib.right_t_left_mm;
  Eigen::Matrix3d t_cross;
  t_cross << 0.0, -t.z(), t.y(), t.z(), 0.0, -t.x(), -t.y(), t.x(), 0.0;
  return t_cross * calib.right_R_left;
}

Eigen::Vector3d RightEpipolarLine(const Eigen::Matrix3d& essential,
                                  const Eigen::Vector2d& xy_left) {
  const Eigen::Vector3d line = essential * Eigen::Vector3d(xy_left.x(), xy_left.y(), 1.0);
  const double norm = line.head<2>().norm();
  if (!(norm > 1e-12 * line.norm()) || norm == 0.0) return Eigen::Vector3d::Zero();
  return line / norm;
}

double EpipolarDistancePx(const StereoCalibration& calib, const Eigen::Vector2d& left_px,
                          const Eigen::Vector2d& right_px) {
  const Eigen::Vector3d line =
      RightEpipolarLine(EssentialMatrix(calib), UndistortPixel(calib.left, left_px));
  if (line.isZero()) return std::numeric_limits<double>::infinity();
  const Eigen::Vector2d xy_right = UndistortPixel(calib.right, right_px);
  return std::fabs(line.x() * xy_right.x() + line.y() * xy_right.y() + line.z()) * calib.right.fx;
}

double InterpretationPlaneAngleDeg(const StereoCalibration& calib, const Eigen::Vector3d& a_mm,
                                   const Eigen::Vector3d& b_mm) {
  // Right camera centre in the left frame: x_right = R x_left + t is zero at -R^T t.
  const Eigen::Vector3d right_centre_mm = -calib.right_R_left.transpose() * calib.right_t_left_mm;
  const Eigen::Vector3d n_left = a_mm.cross(b_mm);
  const Eigen::Vector3d n_right = (a_mm - right_centre_mm).cross(b_mm - right_centre_mm);
  const double norms = n_left.norm() * n_right.norm();
  if (!(norms > 0.0)) return 0.0;
  // atan2 of |sin| and |cos| of the normals' angle: the planes' angle in [0, 90] degrees.
  const double sin_angle = n_left.cross(n_right).norm() / norms;
  const double cos_angle = std::fabs(n_left.dot(n_right)) / norms;
  return std::atan2(sin_angle, cos_angle) * 180.0 / 3.14159265358979323846;
}

}  // namespace sh
