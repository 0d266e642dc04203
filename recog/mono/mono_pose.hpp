// Pose from one image (the step the thesis's 2-D system lacked, ch. 6.1): a hypothesis of the
// 2-D hashing (model, aspect, 2-D transformation) gives a first 6-D pose; the pose is then
// refined by minimising the reprojection error of the model corners and edges matched to image
// corners and lines, projected through the lens distortion (features are never undistorted for
// this). With a table, the pose is first laid onto a stable face and only heading and position
// on the table are refined, which fixes depth and tilt.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/image/corners.hpp"
#include "recog/image/hough.hpp"
#include "recog/mono/aspect.hpp"
#include "recog/mono/frame2d.hpp"
#include "recog/mono/resting_pose.hpp"
#include "recog/verify/visible_edges.hpp"
#include "tables/aspect_format.hpp"

namespace sh {

// The first 6-D pose of a hypothesis: the similarity part of the 2-D transformation from the
// aspect's normalised image to the scene's (scale, rotation, translation; for affine bases the
// rotation and the geometric mean scale of its polar decomposition) turns the aspect's virtual
// camera pose into one seen along the viewing ray of the mapped centroid, at the depth the scale
// implies. `scene_frame` is in ideal pixels (undistorted normalised coordinates times
// ideal_focal_px).
RigidTransform PoseFromHypothesis(const AspectRecord& aspect, const AspectBasis& basis,
                                  const Frame2d& scene_frame, float ideal_focal_px);

// Image features a pose is fitted to, in distorted pixels as detected.
struct PoseCorner {
  Eigen::Vector2f px{0, 0};
};
struct PoseLine {
  Eigen::Vector2f normal{0, 1};  // unit normal: normal . x = rho on the line
  float rho = 0;
  Eigen::Vector2f dir{1, 0};  // unit direction
  float t0 = 0, t1 = 0;       // supported extent along dir (from the foot of the normal)
};

// Capacities of one match set: further corners and pieces stay unmatched (they still count as
// expected), a defined truncation that the reference models come nowhere near.
inline constexpr int kMaxMatchedCorners = 64;
inline constexpr int kMaxMatchedPieces = 128;

// Model corner / edge piece -> image corner / line.
// NOLINTNEXTLINE(bugprone-reserved-identifier): clang-tidy 14 names the implicit array copy's index
struct PoseMatches {
  struct Point {
    Eigen::Vector3f model{0, 0, 0};
    Eigen::Vector2f px{0, 0};
    int16_t scene = -1;
    uint8_t corner = 0;
  };
  struct Line {
    Eigen::Vector3f a_model{0, 0, 0}, b_model{0, 0, 0};  // ends of the visible piece
    Eigen::Vector2f normal{0, 1};
    float rho = 0;
    int16_t scene = -1;
    uint8_t edge = 0;
  };
  int n_points = 0;
  int n_lines = 0;
  // Model features that could have matched: 2-D corners and long enough edge pieces in view.
  int corners_expected = 0;
  int pieces_expected = 0;
  Point points[kMaxMatchedCorners];
  Line lines[kMaxMatchedPieces];
};

struct MatchConfig {
  float corner_gate_px = 6.0f;   // a model corner takes the nearest image corner this close
  float line_gate_px = 6.0f;     // both ends of an edge piece within this of the image line
  float line_angle_deg = 10.0f;  // and its direction within this angle
  float min_overlap = 0.3f;      // the line's support covers this fraction of the piece
  float min_piece_px = 12.0f;    // shorter visible pieces are not matched
  float min_corner_angle_deg = 20.0f;
};

// Active image features available to the matching (null masks: all active).
struct PoseScene {
  const PoseCorner* corners = nullptr;
  const uint8_t* corner_active = nullptr;
  int n_corners = 0;
  const PoseLine* lines = nullptr;
  const uint8_t* line_active = nullptr;
  int n_lines = 0;
};

// Projects the visible corners and edge pieces of the posed model and matches them with the
// scene's features. `visible` are the model's visible edges at this pose (in this camera).
void MatchFeatures(const CameraIntrinsics& cam, const Model& model,
                   const RigidTransform& cam_T_model, const VisibleEdgeSet& visible,
                   const PoseScene& scene, const MatchConfig& config, PoseMatches* out);

struct FitConfig {
  int iterations = 6;
  float sigma_corner_px = 1.5f;  // residual scales: corners and lines weigh by their accuracy
  float sigma_line_px = 1.0f;
  float huber = 2.0f;  // in sigmas: larger residuals are down-weighted (robust)
};

// Residuals and Jacobian of one fit (about 20 KB: kept by the caller, not on the stack).
struct FitScratch {
  static constexpr int kMaxResiduals = 2 * (kMaxMatchedCorners + kMaxMatchedPieces);
  double r[kMaxResiduals];
  double r_trial[kMaxResiduals];
  double J[kMaxResiduals][6];
};

struct FitResult {
  float rms_px = 0;  // root mean square reprojection error over the matches, pixels
  int iterations = 0;
};

// Gauss-Newton (Levenberg-damped, Huber-weighted) over all six parameters; `cam_T_model` is
// updated in place. Needs at least three matched features.
FitResult FitPose(const CameraIntrinsics& cam, const PoseMatches& matches, const FitConfig& config,
                  FitScratch* scratch, RigidTransform* cam_T_model);

// The same over heading and position on the table, the model resting on face pose->face.
FitResult FitRestingPose(const CameraIntrinsics& cam, const PoseMatches& matches,
                         const TablePlane& table, const StableFaces& faces, const FitConfig& config,
                         FitScratch* scratch, RestingPose* pose);

}  // namespace sh
