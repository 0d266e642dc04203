// Hidden-line computation for posed polyhedral models (general, also non-convex, polyhedra).
//
// An edge is a candidate when at least one of its two faces faces the camera centre (silhouette
// and crease edges; edges between two back faces are hidden). A smooth edge (a facet edge of a
// curved surface) is a candidate only on the silhouette: one face turned to the camera, the
// other away. Each candidate edge is sampled at a
// fixed step of projected length, and every sample is tested by casting the ray from the camera
// centre to the sample point against the model's own front faces (non-convex polygons by the
// crossing-number point-in-polygon test) and against the faces of occluding objects already
// accepted in the scene. The result is exact at the sampling: the verification and the overlay
// read the very same samples.
//
// Samples are uniform in the undistorted projection: sample i of n lies at image fraction
// s = (i + 0.5) / n of the projected segment, which is the 3-D fraction t = s a_z / ((1 - s) b_z +
// s a_z) of the edge a..b (a_z, b_z depths in this camera). Lens distortion bends the spacing by
// well under a sample over the length of an edge.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/verify/view_camera.hpp"

namespace sh {

// Capacities. Runs: an edge is cut into at most this many visible pieces; further pieces are
// dropped (counted in VisibleEdgeSet::dropped_runs), a defined under-count that no object of the
// model set comes close to (the star prism needs at most 3).
inline constexpr int kMaxVisibleRunsPerEdge = 8;
// Samples along one edge. An edge longer than this many steps is sampled more coarsely.
inline constexpr int kMaxSamplesPerEdge = 4096;
// Accepted objects that may occlude the one being verified.
inline constexpr size_t kMaxOccluders = 16;
// A face hides a sample only if the ray meets it this far before the sample: keeps the sample's
// own surface (and touching objects) from hiding it through rounding.
inline constexpr double kOcclusionToleranceMm = 0.01;

// Samples [first, end) of an edge that are visible.
struct VisibleRun {
  uint16_t first = 0;
  uint16_t end = 0;
};

struct VisibleEdge {
  uint8_t edge = 0;                   // index into Model::edges
  uint8_t n_runs = 0;                 // >= 1 in a VisibleEdgeSet
  uint16_t n_samples = 0;             // samples along the whole edge, visible or not
  Eigen::Vector3f a_cam_mm{0, 0, 0};  // edge endpoints (corners a, b) in this camera's frame
  Eigen::Vector3f b_cam_mm{0, 0, 0};
  VisibleRun runs[kMaxVisibleRunsPerEdge] = {};
};

// The visible edges of one posed model in one camera.
// NOLINTNEXTLINE(bugprone-reserved-identifier): clang-tidy 14 names the implicit array copy's index
struct VisibleEdgeSet {
  uint16_t n_edges = 0;  // edges with at least one visible sample
  VisibleEdge edges[kMaxModelEdges] = {};
  int n_candidate_edges = 0;    // edges with a front-facing face
  int n_candidate_samples = 0;  // samples on candidate edges
  int n_visible_samples = 0;    // of which visible
  int dropped_runs = 0;         // runs lost to kMaxVisibleRunsPerEdge (normally 0)
};

// Checks the model record: counts within capacities, indices in range, faces with >= 3 vertices
// and a unit normal. Verification never reads outside the record.
Status CheckModel(const Model& model);

// Smallest depth (z in the camera's frame) of the model's corners.
float MinCornerDepthMm(const ViewCamera& camera, const PosedModel& object);

// Visible edges of `object` in `camera`, hidden by the object itself and by `occluders` (other
// objects, e.g. those already recognised; may be null when n_occluders is 0).
// Errors: invalid model or occluder, more than kMaxOccluders occluders, a non-positive step, or
// a corner of `object` closer than min_depth_mm to the camera plane (kOutOfRange: the pose puts
// the object behind or around the camera, where projection is undefined).
Status ComputeVisibleEdges(const ViewCamera& camera, const PosedModel& object,
                           const PosedModel* occluders, size_t n_occluders, float sample_step_px,
                           float min_depth_mm, VisibleEdgeSet* out);

// Image fraction of sample i of n.
inline float SampleImageFraction(int i, int n) { return (static_cast<float>(i) + 0.5f) / n; }

// The point of the edge, in the camera's frame, that projects (without distortion) at image
// fraction s in [0, 1] of the projected segment.
inline Eigen::Vector3f PointAtImageFraction(const VisibleEdge& e, float s) {
  const float az = e.a_cam_mm.z(), bz = e.b_cam_mm.z();
  const float t = s * az / ((1.0f - s) * bz + s * az);
  return e.a_cam_mm + t * (e.b_cam_mm - e.a_cam_mm);
}

inline bool IsSampleVisible(const VisibleEdge& e, int i) {
  for (int r = 0; r < e.n_runs; ++r) {
    if (i >= e.runs[r].first && i < e.runs[r].end) return true;
  }
  return false;
}

// Largest squared normalised radius (x/z)^2 + (y/z)^2 at which a point can still land in the
// image (image corners, undistorted, plus a margin). Points beyond it are outside the image even
// where the distortion polynomial folds them back into it.
double MaxImageRadius2(const CameraIntrinsics& cam);

// Distorted pixel of a point in the camera's frame; false when it cannot be in the image (behind
// the camera or beyond max_radius2).
bool ProjectInView(const CameraIntrinsics& cam, double max_radius2, const Eigen::Vector3f& x_cam_mm,
                   Eigen::Vector2f* pixel);

}  // namespace sh
