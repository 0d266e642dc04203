#include "recog/stereo/epipolar.hpp"

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

}  // namespace sh
