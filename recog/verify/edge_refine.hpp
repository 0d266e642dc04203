// The last step of a pose: a fit of the posed model's visible edges to the edge pixels of both
// images. Feature-based refinement (recog/hashing) fits 3-D corners and lines, whose stereo
// triangulation errs by a fraction of a millimetre in depth; the edge pixels themselves are
// measured to about a pixel in each image, which pins the rotation down further.
//
// Each iteration samples the visible edges (hidden lines and the occluders removed, as the
// verifier does), looks along each sample's image normal for the nearest edge pixel whose
// gradient is perpendicular to the edge, and takes one robust Gauss-Newton step (Huber weights)
// on the signed normal distances of both images over the six pose parameters (rotation about
// the model origin, translation), with Jacobians by finite differences of the projection. The
// refined pose is kept only if it confirms at least as many samples within inlier_px as the
// start and moved little (a safeguard against sliding onto a neighbour's edges).
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/image/edge_map.hpp"
#include "recog/verify/view_camera.hpp"

namespace sh {

struct EdgeRefineConfig {
  int iterations = 6;
  float search_px = 3.0f;       // how far along the normal an edge pixel is looked for
  float max_angle_deg = 15.0f;  // gradient within this of the normal
  float huber_px = 1.0f;        // residuals beyond this are down-weighted
  float inlier_px = 1.0f;       // "confirmed" for the keep-or-discard test
  float sample_step_px = 2.0f;  // spacing of the samples along the projected edges
  int min_samples = 40;         // both images together; fewer: no refinement
  float max_shift_mm = 3.0f;    // larger moves are discarded
  float max_turn_deg = 3.0f;
};

struct EdgeRefineResult {
  bool refined = false;                         // the pose was replaced
  int samples = 0;                              // samples with an edge pixel found, last iteration
  float inliers_before = 0, inliers_after = 0;  // samples confirmed within inlier_px
  float rms_px_before = 0, rms_px_after = 0;    // of the found residuals
};

// Refines `pose` (model -> left camera) in place; leaves it unchanged when the fit does not
// improve it. Errors: invalid model, edge maps that do not match the calibration.
Status RefinePoseOnEdges(const StereoCalibration& calib, const ConstEdgeMapView& left_edges,
                         const ConstEdgeMapView& right_edges, const Model& model,
                         const PosedModel* occluders, size_t n_occluders,
                         const EdgeRefineConfig& config, RigidTransform* pose,
                         EdgeRefineResult* result);

}  // namespace sh
