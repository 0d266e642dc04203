// Aspect models (thesis 6.3): the projection of a 3-D model seen from one direction of its
// viewing sphere, with hidden lines and points removed by the exact hidden-line computation of
// recog/verify (self-occlusion of non-convex models included; partly hidden edges keep their
// visible pieces). An aspect holds the 2-D corners and line segments an image of the object
// would show, in the normalised image coordinates (x/z, y/z) of a virtual camera placed
// `distance_factor` times the model's mean corner radius from its centroid.
#pragma once

#include <Eigen/Core>
#include <bitset>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/model/model.hpp"
#include "recog/verify/visible_edges.hpp"

namespace sh {

// Segments per aspect: one per visible piece of an edge; an edge of the reference models is
// cut into at most three pieces (the star), so twice the edge capacity is ample. More pieces
// are dropped (counted in AspectView::dropped_segments).
inline constexpr int kMaxAspectSegments = 2 * kMaxModelEdges;

struct AspectConfig {
  // Virtual camera distance from the centroid, in mean corner radii (thesis: 10, comparable
  // to the distance of the objects in the experiments).
  float distance_factor = 10.0f;
  // A visible corner is a 2-D corner when two visible edges leave it at an angle between this
  // and 180 degrees minus this (a corner detector cannot see a straight or folded-flat junction).
  float min_corner_angle_deg = 20.0f;
  // Visible pieces shorter than this fraction of the aspect's radius are dropped (a line
  // detector would not find them).
  float min_segment_fraction = 0.15f;
  // Spacing of the hidden-line samples as a fraction of the aspect's radius.
  float sample_fraction = 0.0025f;
};

struct AspectCorner {
  uint8_t corner = 0;        // model corner index
  Eigen::Vector2f xy{0, 0};  // normalised virtual image coordinates
};

struct AspectSegment {
  uint8_t edge = 0;         // model edge index
  Eigen::Vector2f a{0, 0};  // visible piece, normalised virtual image coordinates
  Eigen::Vector2f b{0, 0};
};

// NOLINTNEXTLINE(bugprone-reserved-identifier): clang-tidy 14 names the implicit array copy's index
struct AspectView {
  Eigen::Vector3f dir_model{0, 0, 1};  // from the centroid towards the virtual camera
  RigidTransform cam_T_model;          // model -> virtual camera (centroid on the optical axis)
  float distance_mm = 0;               // virtual camera to centroid
  float radius = 0;  // largest distance of a visible corner from the image origin (normalised)
  int n_corners = 0;
  int n_segments = 0;
  int dropped_segments = 0;
  AspectCorner corners[kMaxModelCorners];
  AspectSegment segments[kMaxAspectSegments];
};

// A set of model corners (bit i: corner i).
using CornerMask = std::bitset<kMaxModelCorners>;

// The corners an image shows as 2-D corners: ends of visible edges where two
// visible edges leave at an angle between min_angle_deg and 180 - min_angle_deg in the image; of a
// part with curved surfaces, only hashed corners (model_features.hpp).
// `projected` holds every corner's image position (any units).
CornerMask VisibleCorners2d(const Model& model, const VisibleEdgeSet& visible,
                            const Eigen::Vector2f* projected, float min_angle_deg);

// Centroid of the model's corners and their mean distance from it.
Eigen::Vector3f ModelCentroid(const Model& model);
float MeanCornerRadiusMm(const Model& model);

// The virtual camera looking at the centroid from `dir_model` at `distance_mm`: optical axis
// through the centroid, image x axis perpendicular to the model's z axis (to its x axis when
// looking along z).
RigidTransform AspectCamera(const Model& model, const Eigen::Vector3f& dir_model,
                            float distance_mm);

// Projects `model` seen from `dir_model` (need not be normalised). Errors: an invalid model
// record or configuration, a zero direction.
Status ComputeAspect(const Model& model, const Eigen::Vector3f& dir_model,
                     const AspectConfig& config, AspectView* out);

}  // namespace sh
