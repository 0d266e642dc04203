// 2-D localisation of a planar face from feature correspondences (seed 001, section V.C):
// affine least squares with outlier removal over three iterations (correspondences whose error
// exceeds three times the mean error are dropped), then a full homography over those that
// remain; and the face's pose from that homography.
//
// Face points are in face millimetres (a, b); image points in ideal (undistorted) pixels, so
// that lens distortion does not bend the planar mapping.
#pragma once

#include <Eigen/Core>

#include "recog/base/vector.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::texture {

struct PlanarMatch {
  float a_mm = 0, b_mm = 0;  // on the face
  float x_px = 0, y_px = 0;  // in the image (ideal pixels)
  uint16_t keypoint = 0;     // scene keypoint index (bookkeeping for the caller)
  uint32_t feature = 0;      // database feature index
};

struct PlanarFitConfig {
  int affine_iterations = 3;
  float outlier_factor = 3.0f;  // drop errors above this times the mean error
  int min_matches = 5;
  float max_mean_error_px = 2.0f;
  // When the rounds above fail, the matches are fitted again from the largest set an affine
  // map through three of them explains within consensus_px (KeepAffineConsensus); 0 samples:
  // no second attempt.
  int consensus_samples = 256;
  float consensus_px = 3.0f;
};

struct PlanarFit {
  Eigen::Matrix3d image_H_face = Eigen::Matrix3d::Identity();  // (x, y, 1) ~ H (a, b, 1)
  int matches = 0;                                             // kept after the outlier removal
  double mean_error_px = 0;  // of the homography over the kept matches
  bool accepted = false;     // >= min_matches kept and mean error below the limit
};

// Fits and filters in place: `matches` keeps the correspondences that survive (order not
// kept). Returns the fit; accepted tells whether the face counts as found.
PlanarFit FitFacePlane(Vector<PlanarMatch>& matches, const PlanarFitConfig& config);

// Keeps the largest set of matches that an affine map through three of them explains within
// config.consensus_px (every triple when there are at most consensus_samples of them, else that
// many from a fixed pseudo-random sequence: deterministic). For clusters with more gross
// outliers than the mean-based rounds of FitFacePlane remove: a print element repeated on a
// face, matched at several places, pulls the least-squares fit towards it. False (matches
// unchanged) when no triple spans a map.
bool KeepAffineConsensus(Vector<PlanarMatch>& matches, const PlanarFitConfig& config);

// A face no nearer than min_depth_mm: between a corner and the matches' centroid the
// homography's w (depth up to a factor) changes by at most their distance over that depth.
// When the fit's homography exceeds that at a corner (corners_ab_mm, face millimetres), its
// perspective is that of noise (a few matches on part of a small face fix it poorly, and the
// face's contour extrapolated from it goes astray): it is replaced by the matches' affine map.
// True when replaced.
bool LimitPerspective(const float (*corners_ab_mm)[2], int n_corners,
                      const Vector<PlanarMatch>& matches, double min_depth_mm, PlanarFit* fit);

// Least-squares affine map (x, y) = A (a, b, 1) of the matches (2 x 3); false when degenerate
// (fewer than three non-collinear points).
bool FitAffine(const Vector<PlanarMatch>& matches, Eigen::Matrix<double, 2, 3>* affine);
bool FitAffine(const PlanarMatch* matches, size_t count, Eigen::Matrix<double, 2, 3>* affine);

// Least-squares homography with h9 = 1 (the paper's linear system, on coordinates centred and
// scaled for conditioning); false when degenerate (fewer than four points in general position).
bool FitHomography(const Vector<PlanarMatch>& matches, Eigen::Matrix3d* image_H_face);

Eigen::Vector2d ApplyHomography(const Eigen::Matrix3d& H, double a, double b);

// Largest singular value of the homography's Jacobian at face point (a, b): image pixels per
// millimetre along the face direction least foreshortened. A face at depth Z (along the viewing
// ray) seen by a camera of focal length f shows about f / Z there, whatever its tilt: a depth
// estimate that stays stable when the homography's perspective terms are not (a narrow face).
double MaxImageScale(const Eigen::Matrix3d& image_H_face, double a, double b);

// Pose of the face frame (a, b, 0) in the camera from a homography to ideal pixels of a camera
// with focal lengths fx, fy and principal point cx, cy: H ~ K [r1 r2 t]. The rotation is the
// nearest one to [r1 r2 r1 x r2]; false when the homography puts the face behind the camera or is
// degenerate.
bool PoseFromHomography(const Eigen::Matrix3d& image_H_face, double fx, double fy, double cx,
                        double cy, RigidTransform* cam_T_face);

}  // namespace sh::texture
