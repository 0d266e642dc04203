// "Sloppy" stereo (thesis 3.2.2, 4.2.3): every left/right pair of 2-D features that meets the
// geometric constraints becomes a 3-D feature, without arbitration between candidates. Spurious
// matches are expected; geometric hashing and verification sort them out, and each 3-D feature
// keeps the indices of its two 2-D features (FeatureSource) so that they can be removed together.
//
// Points: for a left corner, every right corner within epipolar_tolerance_px (T_s) of its
// epipolar curve (see epipolar.hpp) is a candidate; it is triangulated as the midpoint of the
// shortest segment between the two viewing rays and kept when both rays meet in front of their
// cameras, the rays pass within max_ray_gap_mm of each other, and the point lies in the working
// volume. Quality = the smaller of the two corner strengths.
//
// To avoid testing all N x M pairs, right corners are sorted by the angle of their epipolar
// plane around the baseline (a rectification-free "row" coordinate, valid for any camera
// arrangement and with distortion). Only corners whose angle is within asin(T_s / fx / sin b) of
// the left corner's are examined, b being the smallest angle between a right viewing ray and the
// baseline; the exact epipolar distance then decides. Near-epipole rays (b small) widen the
// window up to the full N x M scan, which is still correct. Corners on the opposite half of an
// epipolar plane are never paired: their rays could only meet on the baseline.
//
// Lines: every left/right pair. Each 2-D line and its camera centre span a plane (fitted through
// the viewing rays of the line's supported extent: both ends and the middle, so that distortion
// is honoured); the two planes meet in a 3-D line. Pairs whose planes are within
// min_plane_angle_deg of parallel (lines close to the epipolar direction) are rejected as
// degenerate. Each image's supported segments are back-projected onto the 3-D line, clipped to
// the working volume, and the pair is accepted when the two supports overlap by at least
// min_overlap_mm. SceneLine a..b spans the overlap; quality = overlap length in mm.
//
// Capacity: outputs are bounded Vectors (the Scene's). When one is full, matching stops, the
// features found so far are kept (in left-feature order) and kResourceExhausted is returned with
// the stats saying so; the caller may carry on with the truncated scene.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/scene/scene.hpp"
#include "recog/stereo/stereo_features.hpp"
#include "recog/stereo/triangulation.hpp"
#include "recog/stereo/working_volume.hpp"

namespace sh {

struct SloppyStereoConfig {
  WorkingVolume volume;                // default: a large box in front of the left camera
  float epipolar_tolerance_px = 2.0f;  // T_s
  float max_ray_gap_mm = 5.0f;         // points: largest distance between the two rays
  float min_overlap_mm = 10.0f;        // lines: least common support
  float min_plane_angle_deg = 3.0f;    // lines: planes closer to parallel are degenerate
};

struct PointStereoStats {
  size_t within_tolerance = 0;  // pairs within T_s of the epipolar curve
  size_t rejected_behind = 0;   // rays meet behind a camera
  size_t rejected_gap = 0;      // rays too far apart
  size_t rejected_volume = 0;   // outside the working volume
  size_t accepted = 0;
  bool truncated = false;  // output full: matching stopped early
};

struct LineStereoStats {
  size_t unusable_lines = 0;       // lines without support or without a well-defined plane
  size_t pairs = 0;                // pairs of usable lines examined
  size_t rejected_degenerate = 0;  // planes nearly parallel
  size_t rejected_volume = 0;      // 3-D line misses the working volume
  size_t rejected_overlap = 0;     // supports overlap less than min_overlap_mm
  size_t accepted = 0;
  bool truncated = false;
};

// Holds the calibration-derived constants and the static workspace of one stereo head
// (about 490 KiB: allocate it once, e.g. as a static object, not on a small stack).
class SloppyStereo {
 public:
  // Checks the configuration (tolerances finite and positive, volume non-empty) and the
  // calibration (ValidateStereoCalibration), then precomputes the epipolar frame.
  Status Configure(const StereoCalibration& calib, const SloppyStereoConfig& config);

  // Clears `points` and fills it with every accepted left/right corner pair. Inputs at most
  // kMaxStereoCorners each, finite coordinates.
  Status MatchPoints(const StereoPoint2D* left, size_t left_count, const StereoPoint2D* right,
                     size_t right_count, Vector<ScenePoint>& points,
                     PointStereoStats* stats = nullptr);

  // Clears `lines` and fills it with every accepted left/right line pair. Inputs at most
  // kMaxStereoLines each, finite, unit directions, segment_count <= kMaxStereoLineSegments.
  Status MatchLines(const StereoLine2D* left, size_t left_count, const StereoLine2D* right,
                    size_t right_count, Vector<SceneLine>& lines, LineStereoStats* stats = nullptr);

  const StereoCalibration& calibration() const { return calib_; }
  const SloppyStereoConfig& config() const { return config_; }

 private:
  struct RightCorner {
    Eigen::Vector2d xy;        // right normalised coordinates
    Eigen::Vector3d ray_left;  // unit viewing ray, left frame
    double plane_angle = 0;    // epipolar-plane angle around the baseline, radians
  };
  // A 2-D line prepared for pairing: its back-projected plane and its segment end rays.
  struct PreparedLine {
    bool usable = false;
    Plane3 plane;  // left frame
    uint8_t segment_count = 0;
    // Unit rays in the left frame, 2 per segment. Float halves the workspace; 1e-7 rad of
    // rounding is 0.1 um at 1 m.
    Eigen::Vector3f ray_left[2 * kMaxStereoLineSegments];
  };

  Status PrepareLines(const StereoLine2D* lines, size_t count, bool is_left, PreparedLine* prepared,
                      size_t* unusable);
  double PlaneAngle(const Eigen::Vector3d& ray_left) const;
  bool AcceptPoint(const Eigen::Vector3d& ray_left, const RightCorner& right,
                   PointStereoStats& stats, Eigen::Vector3d* p_mm) const;

  bool configured_ = false;
  StereoCalibration calib_;
  SloppyStereoConfig config_;
  Eigen::Matrix3d essential_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d left_R_right_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d right_centre_mm_ = Eigen::Vector3d::Zero();  // left frame
  Eigen::Vector3d baseline_u_ = Eigen::Vector3d::UnitY();      // with baseline_v_, spans the
  Eigen::Vector3d baseline_v_ = Eigen::Vector3d::UnitZ();      // plane normal to the baseline
  Eigen::Vector3d baseline_dir_ = Eigen::Vector3d::UnitX();

  RightCorner right_[kMaxStereoCorners];
  uint16_t order_[kMaxStereoCorners];  // right corners sorted by plane_angle
  double sorted_angle_[kMaxStereoCorners];
  PreparedLine left_lines_[kMaxStereoLines];
  PreparedLine right_lines_[kMaxStereoLines];
};

}  // namespace sh
