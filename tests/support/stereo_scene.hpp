// Synthetic stereo rigs and scenes shared by the stereo tests and the benchmark.
#pragma once

#include <Eigen/Geometry>
#include <random>

#include "recog/camera/camera_model.hpp"
#include "recog/stereo/stereo_features.hpp"
#include "tests/support/calibrations.hpp"

namespace sh::testing {

// A random point in the common field of view, 500..900 mm from the left camera.
inline Eigen::Vector3d RandomScenePoint(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double z = 700.0 + 200.0 * u(rng);
  return {60.0 + 0.2 * z * u(rng), 0.2 * z * u(rng), z};
}

inline bool ProjectBoth(const StereoCalibration& c, const Eigen::Vector3d& p_left,
                        Eigen::Vector2d* left_px, Eigen::Vector2d* right_px) {
  const Eigen::Vector3d p_right = c.right_R_left * p_left + c.right_t_left_mm;
  if (!ProjectToPixel(c.left, p_left, left_px) || !ProjectToPixel(c.right, p_right, right_px)) {
    return false;
  }
  auto inside = [](const CameraIntrinsics& cam, const Eigen::Vector2d& px) {
    return px.x() >= 0 && px.y() >= 0 && px.x() < cam.width && px.y() < cam.height;
  };
  return inside(c.left, *left_px) && inside(c.right, *right_px);
}

// The 2-D line through the projections of a 3-D segment, with the segment as its support.
// Without distortion it is exact; with distortion it is the chord of the curved image.
inline StereoLine2D ChordLine(const Eigen::Vector2d& a_px, const Eigen::Vector2d& b_px) {
  StereoLine2D line;
  line.point_px = (0.5 * (a_px + b_px)).cast<float>();
  line.direction = (b_px - a_px).normalized().cast<float>();
  line.segment_count = 1;
  line.segments[0] = {static_cast<float>(a_px.x()), static_cast<float>(a_px.y()),
                      static_cast<float>(b_px.x()), static_cast<float>(b_px.y())};
  return line;
}

}  // namespace sh::testing
