// Pose refinement of a hypothesis with all the scene features that support it (thesis 4.5).
//
// Correspondences: each model corner takes the nearest active scene point within the gate; each
// model edge takes the active scene line with the smallest vote distance (eq. 4.4) within the
// gate. Then Gauss-Newton over the 6 pose parameters minimises the summed squared vote
// distances, with analytic Jacobians:
//   point:  r = x - q,                           x = R p + t
//   line:   r1 = (I - v v^T)(x0 - s),            x0 = R c + t  (segment centre)
//           r2 = (L / sqrt 12) (v x u),          u  = R d      (segment direction)
// |r1|^2 + |r2|^2 is eq. 4.4 exactly. The selection is repeated once with the refined pose.
#pragma once

#include <cstdint>

#include "recog/geometry/rigid_transform.hpp"
#include "recog/model/model.hpp"
#include "recog/scene/scene.hpp"

namespace sh {

class SceneGrid;

struct RefineConfig {
  float gate_sigmas = 2.0f;  // correspondences within gate_sigmas * sigma
  int iterations = 5;        // Gauss-Newton steps per selection round
  int rounds = 2;            // select, estimate, select again, estimate again
};

// Model feature -> scene feature index (or -1) after refinement. The arrays are written for every
// corner and edge of the model by whoever fills the struct, so they are not zeroed on creation.
struct Correspondences {  // NOLINT(cppcoreguidelines-pro-type-member-init)
  int16_t point_of_corner[kMaxModelCorners];
  int16_t line_of_edge[kMaxModelEdges];
  int matched_points = 0;
  int matched_lines = 0;
};

struct RefineInput {
  const Model* model = nullptr;
  const Scene* scene = nullptr;
  const uint8_t* point_active = nullptr;  // per scene point, non-zero if still available
  const uint8_t* line_active = nullptr;
  const SceneGrid* point_grid = nullptr;  // grid over scene.points (same indices)
  float sigma_point_mm = 3.0f;
  float sigma_line_mm = 3.0f;
};

struct RefineResult {
  RigidTransform cam_T_model;
  Correspondences matches;
  float rms_mm = 0.0f;  // root mean squared vote distance over the final correspondences
};

RefineResult RefinePose(const RefineInput& in, const RigidTransform& initial_cam_T_model,
                        const RefineConfig& config);

// Selection only (no estimation), e.g. to score a pose.
void SelectCorrespondences(const RefineInput& in, const RigidTransform& cam_T_model, float gate_mm,
                           Correspondences* out);

// Squared vote distance between a model segment (centre, unit direction, length) and an
// infinite scene line (point s, unit direction v): eq. 4.4,
//   |w|^2 - (v . w)^2 + length^2 / 12 (1 - (v . dir)^2)  with w = centre - s.
// Both terms are evaluated as squared norms of the components perpendicular to v: the same value
// without the cancellation of the difference form, which goes negative in float far from the
// camera (and a negative distance must not turn into a vote).
inline float SegmentLineDistance2(const Eigen::Vector3f& centre, const Eigen::Vector3f& dir,
                                  float length, const Eigen::Vector3f& s,
                                  const Eigen::Vector3f& v) {
  const Eigen::Vector3f w = centre - s;
  const Eigen::Vector3f w_perp = w - v.dot(w) * v;
  const Eigen::Vector3f dir_perp = dir - v.dot(dir) * v;
  return w_perp.squaredNorm() + length * length * (1.0f / 12.0f) * dir_perp.squaredNorm();
}

}  // namespace sh
