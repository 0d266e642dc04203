// Final pose of a printed model from every consistent correspondence of both images (seed 001
// section V.D, refined): Gauss-Newton over the six pose parameters minimising, in pixels,
//  - for each matched feature, the distance between its image position in the left image and
//    the projection of its model point, and
//  - for each stereo point on a face, the distance between its right-image position and the
//    projection of the point where its left viewing ray meets the face's plane under the pose
//    (the plane's transfer from the left to the right image).
// The first term fixes the print's position and rotation in the image, the second the depth and
// the tilt of every face found. Observations whose error exceeds gate_factor times the median
// (and min_gate_px) are set aside and the solve is repeated, twice (an observation set aside
// under the first, biased pose may come back).
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::texture {

inline constexpr size_t kMaxPoseObservations = 2048;

struct PoseFeatureObservation {
  Eigen::Vector3d model_mm;
  Eigen::Vector2d left_px;  // distorted, as detected
  double sigma_px = 1.0;    // expected error (grows with the feature's scale)
};

struct PoseStereoObservation {
  Eigen::Vector2d left_px, right_px;   // distorted
  Eigen::Vector3d plane_normal_model;  // the face's plane in the model: n . x = d
  double plane_d_mm = 0.0;
};

struct PoseRefineConfig {
  int iterations = 8;
  double stereo_sigma_px = 0.3;
  double gate_factor = 3.0;
  double min_gate_px = 1.5;
};

struct PoseRefineStats {
  int features_used = 0;
  int stereo_used = 0;
  double feature_rms_px = 0;
  double stereo_rms_px = 0;
};

class TexturePoseRefiner {
 public:
  // Refines cam_T_model in place (left camera frame). False, leaving the pose unchanged, when
  // there are too few observations to fix six parameters or the solve diverges.
  bool Refine(const StereoCalibration& calib, const PoseFeatureObservation* features,
              size_t n_features, const PoseStereoObservation* stereo, size_t n_stereo,
              const PoseRefineConfig& config, RigidTransform* cam_T_model, PoseRefineStats* stats);

 private:
  // Weighted residuals of all active observations under the pose (R, t); returns the count.
  size_t Residuals(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double* out) const;
  bool Solve(const PoseRefineConfig& config, Eigen::Matrix3d* R, Eigen::Vector3d* t);
  // Pixel error (x, y) of one observation under (R, t); false when it does not project.
  bool FeatureError(size_t i, const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double* e) const;
  bool StereoError(size_t i, const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double* e) const;
  // Keeps the observations whose error is within the gate (see the file comment).
  void Gate(const PoseRefineConfig& config, const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

  const StereoCalibration* calib_ = nullptr;
  const PoseFeatureObservation* features_ = nullptr;
  const PoseStereoObservation* stereo_ = nullptr;
  size_t n_features_ = 0, n_stereo_ = 0;
  bool active_[2 * kMaxPoseObservations] = {};
  Eigen::Vector3d rays_[kMaxPoseObservations];  // left viewing rays of the stereo points
  double residuals_[4 * kMaxPoseObservations] = {};
  double shifted_[4 * kMaxPoseObservations] = {};
  double jacobian_[6][4 * kMaxPoseObservations] = {};
};

}  // namespace sh::texture
