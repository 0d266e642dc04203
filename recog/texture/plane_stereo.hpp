// 6-D localisation of a found face by stereo (seed 001, section V.D, steps 1-4): Shi-Tomasi
// points inside the face's contour in the left image, their sub-pixel correspondence in the
// right image by zero-mean normalised cross-correlation (ZNCC) along the epipolar curve (images
// neither rectified nor undistorted: the camera model with its distortion maps every candidate),
// triangulation, and a RANSAC plane through the 3-D points.
//
// The face's provisional plane (its pose from the homography) bounds the search along the
// epipolar curve to a depth interval around it and gives the local warp of the correlation
// window from the left to the right image (the cameras may be rotated against each other, and
// the face is seen at an angle); the depth itself comes from the correlation alone.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "recog/base/vector.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/image/image.hpp"
#include "recog/stereo/triangulation.hpp"
#include "recog/texture/float_planes.hpp"

namespace sh::texture {

inline constexpr size_t kMaxFaceStereoPoints = 256;
inline constexpr int kMaxZnccRadiusPx = 6;
inline constexpr int kMaxEpipolarSamples = 512;

struct PlaneStereoConfig {
  int max_points = 120;        // Shi-Tomasi points per face (strongest)
  int nms_radius_px = 3;       // a point is the maximum of its (2 r + 1)^2 neighbourhood
  float min_strength = 2e-4f;  // smaller structure-tensor eigenvalue (intensities on [0, 1])
  float min_relative_strength = 0.02f;  // of the strongest inside the contour
  float contour_margin_px = 5.0f;       // points keep this far inside the face's contour
  int window_radius_px = 3;             // ZNCC window (2 r + 1)^2
  float depth_search_fraction = 0.12f;  // search +- this fraction of the provisional depth
  float min_zncc = 0.8f;
  // RANSAC plane
  int ransac_iterations = 100;
  float plane_tolerance_mm = 1.5f;
  int min_plane_points = 8;
  // A second correlation pass with the measured plane as prior when the first found fewer than
  // half the points, or a plane more than prior_retry_deg from the prior; its prior may come
  // from as few as min_prior_points (texture_recognizer.cpp, LocateFace).
  int min_prior_points = 5;
  float prior_retry_deg = 10.0f;
};

struct StereoPoint {
  Eigen::Vector2f left_px = Eigen::Vector2f::Zero();   // distorted, as in the image
  Eigen::Vector2f right_px = Eigen::Vector2f::Zero();  // distorted
  Eigen::Vector3f x_mm = Eigen::Vector3f::Zero();      // left camera frame
  float zncc = 0.0f;
  bool inlier = false;  // of the plane fit
};

// Shi-Tomasi points (local maxima of the smaller eigenvalue plane) inside `contour` (a simple
// polygon in image pixels, either orientation), at least the margin inside it; the strongest
// max_points, strongest first.
void SelectContourPoints(const ConstFloatView& min_eigenvalue, const Eigen::Vector2f* contour,
                         int n_contour, const PlaneStereoConfig& config,
                         Vector<Eigen::Vector2f>& points);

// Correlation matcher over one stereo pair (grey images of the calibration's size).
class PlaneStereoMatcher {
 public:
  void Reset(const StereoCalibration* calib, ConstGrayView left, ConstGrayView right);

  // Finds the right-image correspondence of left_px (integer pixel, distorted) with the plane
  // `prior` (left camera frame) bounding the depth search and shaping the window. False when
  // nothing correlates above min_zncc, the best match lies at the end of the search interval,
  // or the point does not see the plane.
  bool Match(const Eigen::Vector2f& left_px, const Plane3& prior, const PlaneStereoConfig& config,
             StereoPoint* out) const;

 private:
  const StereoCalibration* calib_ = nullptr;
  ConstGrayView left_{}, right_{};
};

struct PlaneFitStats {
  int points = 0;
  int inliers = 0;
  double mean_abs_mm = 0;  // of the inliers' distances to the plane
  double max_abs_mm = 0;
  double rms_mm = 0;
};

// RANSAC plane through the points (deterministic: fixed-seed sampling), refined by least
// squares over the inliers; marks StereoPoint::inlier. The plane's normal points towards the
// camera (n . x = d with d < 0 for a plane in front of it). False with fewer than
// min_plane_points inliers.
bool FitPlaneRansac(Vector<StereoPoint>& points, const PlaneStereoConfig& config, Plane3* plane,
                    PlaneFitStats* stats);

// Least-squares plane through points (smallest eigenvector of their covariance).
bool FitPlaneLeastSquares(const Eigen::Vector3d* points, int count, Plane3* plane);

// Where the viewing ray (unit direction from the origin) meets the plane; false when parallel
// or behind the camera.
bool IntersectRayPlane(const Eigen::Vector3d& ray, const Plane3& plane, Eigen::Vector3d* x);

}  // namespace sh::texture
