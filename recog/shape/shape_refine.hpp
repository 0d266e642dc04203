// Pose refinement of a colour part in both images at once: the model's visible silhouette
// edges and sharp creases are sampled, each sample looks along its image normal for the edge
// the image shows there, and Gauss-Newton moves the 6-D pose so that the projected samples land
// on those edges (a moving-edges tracker, with stereo: two images constrain depth as well as
// the image-plane position).
//
// What counts as an edge depends on the model edge:
//   - a silhouette edge (one adjacent face turned to the camera) must show the part's colour
//     class on its inner side and another class (table, shadow, another part) on its outer
//     side; the transition nearest the prediction is taken, located to a fraction of a pixel
//     at the colour gradient's peak;
//   - a crease (both faces visible) whose faces meet at more than min_crease_angle_deg shows as
//     a change of shading inside the part: the colour gradient's peak nearest the prediction,
//     with the part's class on both sides.
// The can's side creases (7.5 degrees) fall under the angle and are not used; its outline is.
// Samples hidden by the model itself or by objects already accepted (occluders) are skipped;
// residuals are weighted with Huber's function so that edges of unknown occluders do little.
//
// Visibility is recomputed every few iterations (samples are kept as model points between),
// since a pose that moves by millimetres changes which edges show very little.
//
// No heap: the visible-edge set and the samples live in the refiner (static storage of its
// owner).
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/image/frame.hpp"
#include "recog/shape/colour_classes.hpp"
#include "recog/shape/edge_search.hpp"
#include "recog/verify/view_camera.hpp"
#include "recog/verify/visible_edges.hpp"

namespace sh {

struct ShapeRefineConfig {
  float sample_step_px = 3.0f;
  float min_crease_angle_deg = 25.0f;
  int iterations = 12;
  // Search half-width along the normal: from the first to the last iteration, linearly.
  float search_start_px = 12.0f;
  float search_end_px = 3.0f;
  // Colour gradient an edge must reach: Euclidean R'G'B' difference of neighbouring samples.
  float min_edge_contrast = 10.0f;
  float huber_px = 1.5f;
  // A sample is confirmed when the image's edge lies within this distance of it at the end.
  float confirm_px = 1.5f;
  // Stop when the last update moved every model point by less than this (mm).
  float converged_mm = 0.01f;
  // Visible edges are recomputed every this many iterations.
  int visibility_every = 3;
  // The result's fit: at the pose reached, with fresh visibility and the narrowest search (true),
  // or that of the last iteration's pass, one update earlier (false: enough to rank hypotheses,
  // and a visibility computation and a pass cheaper).
  bool final_fit = true;
  // Give up (kNotFound) when the first pass finds an edge for less than this share of an image's
  // samples: a start that far from what the images show does not verify (0: never). An image
  // without samples (the part outside its view) gives up too: the verifier needs both images.
  float min_start_share = 0.0f;
};

Status CheckShapeRefineConfig(const ShapeRefineConfig& config);

// Fit of one image at the final pose.
struct EdgeFit {
  int samples = 0;    // visible, in-image samples of the used edges
  int found = 0;      // with an edge within the last search range
  int confirmed = 0;  // with an edge within confirm_px
  float score() const { return samples > 0 ? static_cast<float>(confirmed) / samples : 0.0f; }
};

struct ShapeRefineResult {
  EdgeFit fit[2];  // left, right
  int iterations = 0;
  bool converged = false;
};

// The images refinement reads: each camera's R'G'B' image and the class image of its
// segmentation.
struct ShapeImages {
  ImageView<const Rgb8> rgb[2];
  ConstGrayView classes[2];
};

// Capacity of edge samples per image; longer outlines are sampled more coarsely.
inline constexpr int kMaxRefineSamples = 2048;

class ShapeRefiner {
 public:
  // `object.cam_T_model` is the start and receives the result. `colour` is the part's class.
  // Errors: bad configuration, images that do not match the calibration, a pose that puts the
  // model behind a camera (kOutOfRange), too few samples to solve (kFailedPrecondition).
  Status Refine(const StereoCalibration& calib, const ShapeImages& images, uint8_t colour,
                PosedModel* object, const PosedModel* occluders, size_t n_occluders,
                const ShapeRefineConfig& config, ShapeRefineResult* out);

 private:
  // A point on a used model edge, in the model frame.
  struct Sample {
    Eigen::Vector3f x_model;
    Eigen::Vector3f along_model;   // edge direction
    Eigen::Vector3f inward_model;  // into the visible face (silhouettes); zero for creases
  };
  Status Collect(const ViewCamera& view, const PosedModel& object, const PosedModel* occluders,
                 size_t n_occluders, const ShapeRefineConfig& config, int camera);

  VisibleEdgeSet visible_;
  Sample samples_[2][kMaxRefineSamples];
  int n_samples_[2] = {0, 0};
};

}  // namespace sh
