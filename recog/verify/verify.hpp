// Hypothesis verification (method notes section 5): the visible edges of the posed model are
// sampled, projected into both images with lens distortion, and each sample is confirmed by an
// edge pixel near it whose gradient is perpendicular to the projected edge. The hypothesis is
// accepted when a large enough fraction of the samples is confirmed in both images.
//
// No heap: one VisibleEdgeSet (2.9 KB) at a time and the occluder table of ComputeVisibleEdges
// (about 2.5 KB for kMaxOccluders) live on the stack.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/image/edge_map.hpp"
#include "recog/image/image.hpp"
#include "recog/verify/view_camera.hpp"
#include "recog/verify/visible_edges.hpp"

namespace sh {

struct VerifyConfig {
  // A sample is confirmed by an edge pixel at most this far from it across the projected edge
  // (searched along the image axis closest to the edge's normal, so that thin oblique edge lines
  // cannot be stepped over).
  float max_distance_px = 4.0f;
  // ... whose gradient direction is within this angle of that normal (modulo 180 degrees).
  float max_angle_deg = 10.0f;
  // Accept when at least this fraction of the in-image samples is confirmed in each image.
  float min_fraction = 0.4f;
  // Fewer in-image samples than this in either image: too little evidence to accept.
  int min_samples = 20;
  // Spacing of the samples along the projected edges.
  float sample_step_px = 1.0f;
  // A model corner closer than this to a camera plane means the pose is behind the camera.
  float min_depth_mm = 1.0f;

  // Faint edges (when the grey image is given, GreyEvidence): an edge between two faces of
  // nearly the same brightness (a crease of a light part under diffuse light, a light part on
  // a light table) steps by a few grey levels, below what an edge detector can tell from noise
  // at one pixel, yet the step is there along the whole edge. A visible model edge of which at
  // most half the samples are confirmed by edge pixels is confirmed whole when the grey levels
  // faint_offset_px to either side of it differ, over all its samples, by a mean step that is
  //   - at least faint_min_step_sigmas noise sigmas and faint_min_step grey levels,
  //   - at least faint_snr times its standard error from the image's noise,
  //   - of the same sign and at least half that size in each quarter of the edge,
  // so that a wrong model's edge crossing a face (no step), a shadow's ramp (no sharp step) or a
  // real edge across it (a step in one place only) stays unconfirmed. Off: only edge pixels.
  bool faint_edges = false;
  float faint_offset_px = 2.0f;
  float faint_min_step_sigmas = 1.5f;
  float faint_min_step = 3.0f;  // grey levels
  float faint_snr = 8.0f;
  int faint_min_samples = 16;  // shorter visible edges are not tested
};

// The grey image behind an edge map, for the faint-edge test. An empty image: no such test.
struct GreyEvidence {
  ConstGrayView image;
  float noise_sigma = 0.0f;  // measured sensor noise, grey levels (0: unknown)
};

enum class VerifyReason : uint8_t {
  kAccepted = 0,
  kBehindCamera,       // a model corner lies behind (or in the plane of) a camera
  kTooFewSamplesLeft,  // fewer than min_samples visible samples inside the left image
  kTooFewSamplesRight,
  kLowScoreLeft,  // confirmed fraction below min_fraction in the left image
  kLowScoreRight,
};

const char* VerifyReasonName(VerifyReason reason);

struct VerifyResult {
  bool accepted = false;
  float score_left = 0.0f;  // confirmed / samples_left, 0 when there are no samples
  float score_right = 0.0f;
  int samples_left = 0;  // visible samples that project inside the left image
  int samples_right = 0;
  int confirmed_left = 0;
  int confirmed_right = 0;
  int faint_edges_left = 0;  // edges confirmed by the faint-edge test
  int faint_edges_right = 0;
  VerifyReason reason = VerifyReason::kAccepted;
};

// Counts of one image.
struct ImageScore {
  int samples = 0;
  int confirmed = 0;
  int faint_edges = 0;  // edges confirmed by the faint-edge test (their samples are in confirmed)
};

// Checks the configuration ranges (distance 0..32 px, angle 0..90 degrees, fraction 0..1, ...).
Status CheckVerifyConfig(const VerifyConfig& config);

// Checks that the edge map is non-null and matches the camera's image size.
Status CheckEdgeMap(const CameraIntrinsics& cam, const ConstEdgeMapView& edges);

// Scores already computed visible edges against one image's edge map (and, with
// config.faint_edges, its grey image).
Result<ImageScore> ScoreVisibleEdges(const ViewCamera& camera, const VisibleEdgeSet& visible,
                                     const ConstEdgeMapView& edges, const VerifyConfig& config,
                                     const GreyEvidence& grey = {});

// Verifies `hypothesis` against both edge maps. `accepted` are objects recognised before, which
// hide parts of the hypothesis (may be null when n_accepted is 0; at most kMaxOccluders).
// Errors (not rejections): bad configuration, edge maps that do not match the calibration, an
// invalid model record, too many occluders. A rejected hypothesis is an ok Result with
// accepted == false and the first failing reason.
Result<VerifyResult> VerifyHypothesis(const StereoCalibration& calib,
                                      const ConstEdgeMapView& left_edges,
                                      const ConstEdgeMapView& right_edges,
                                      const PosedModel& hypothesis, const PosedModel* accepted,
                                      size_t n_accepted, const VerifyConfig& config,
                                      const GreyEvidence& left_grey = {},
                                      const GreyEvidence& right_grey = {});

}  // namespace sh
