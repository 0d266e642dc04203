// Corner points of one grey image: local maxima of the isophote curvature times the cubed
// gradient magnitude, |Iy^2 Ixx - 2 Ix Iy Ixy + Ix^2 Iyy|, with Gaussian derivatives at sigma_c.
//
// Pixel convention (all of recog/image): pixel (x, y) has its centre at (x, y); x grows to the
// right, y downwards.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/image/gaussian.hpp"
#include "recog/image/image.hpp"

namespace sh {

// Most corners reported for one image. When more maxima pass the threshold, the strongest
// kMaxCorners2d are kept (ties: the one found first in raster order).
inline constexpr size_t kMaxCorners2d = 1024;

struct Corner2D {
  float x_px = 0.0f;
  float y_px = 0.0f;
  // Response normalised so that an ideal right-angle corner of contrast 255 (a blurred step
  // quadrant) gives 1.0; scale-invariant (sigma^4 normalisation) and proportional to
  // contrast^3, so 0.1 is about a right-angle corner of contrast 118.
  float strength = 0.0f;
  // How far the gradients around the corner span two directions (with refine_to_vertex, else
  // 1): the smaller eigenvalue of their structure tensor over its trace, at the detected
  // position. 0 on a straight edge, (1 - cos a) / 2 for two edges whose normals differ by a,
  // 0.5 at most. The detector reports points on strong edges too (sensor noise bends the
  // isophotes there); the one-image recogniser takes no basis from them.
  float isotropy = 1.0f;
};

struct CornerConfig {
  float sigma_px = 2.0f;  // sigma_c: scale of the Gaussian derivatives
  // Absolute threshold on the normalised strength (see Corner2D::strength).
  float threshold = 0.02f;
  // Optional relative threshold: fraction of the strongest response in this image; 0 disables.
  // The effective threshold is the larger of the two.
  float relative_threshold = 0.0f;
  int nms_radius_px = 3;  // a corner is the maximum of its (2 r + 1)^2 neighbourhood
  // false (default): Gaussian smoothing, then central differences for the five derivatives. The
  // differences add a blur of their own (variance about 1/4 px^2), so the smoothing uses
  // sqrt(sigma_c^2 - 1/4): about a quarter of the cost of five Gaussian-derivative convolutions.
  // true: the five separable Gaussian-derivative convolutions at sigma_c.
  bool exact_derivatives = false;
  // The curvature maximum of a blurred corner lies inside the corner, about 0.9 sigma_c from the
  // vertex along the bisector for a right angle. With refinement on, each corner is moved to the
  // point that best fits the edge lines around it (gradient-weighted least squares with
  // gradients at refine_sigma_px); the move is kept only if the fit is well conditioned and
  // stays within the refinement window (about 2.5 sigma_c).
  bool refine_to_vertex = true;
  float refine_sigma_px = 1.0f;
  // Scales of at least kCornerReduceSigmaPx (without exact_derivatives) are computed on the image
  // reduced 2x: binomial (1 4 6 4 1) / 16 blur, every second column and row, then sigma_c / 2
  // there, as in a Gaussian scale space. A quarter of the pixels with half the taps each; the
  // maxima are scaled back and the vertex refinement runs on the full image. false: always at
  // full resolution (the reference the reduced path is tested against).
  bool reduce_large_scales = true;
};

inline constexpr float kCornerReduceSigmaPx = 4.0f;

struct CornerStats {
  float max_strength = 0.0f;    // strongest response in the image
  float threshold_used = 0.0f;  // effective threshold
  size_t maxima_found = 0;      // local maxima above the threshold
  size_t maxima_dropped = 0;    // of those, not reported for lack of capacity
  size_t vertex_refined = 0;    // corners moved by the vertex refinement
};

// Largest NMS radius accepted.
inline constexpr int kMaxCornerNmsRadiusPx = 16;

// Checks the configuration; DetectCorners calls it too.
Status ValidateCornerConfig(const CornerConfig& config);

// Detects corners; `corners` is cleared first and holds them sorted by decreasing strength.
// Uses the rings (row bands), the response rows and the reduced image of `scratch`: the response
// is computed twice, a row at a time, first for its maximum (the relative threshold), then for
// the corners of each row once the rows within the NMS radius exist. Fails (and leaves `corners`
// empty) on an invalid image or config.
Status DetectCorners(const ConstGrayView& image, const CornerConfig& config, FilterScratch& scratch,
                     Vector<Corner2D>& corners, CornerStats* stats = nullptr);

// The response DetectCorners computes for `config` on the full-size image (the reduced path of
// the large scales aside), written whole to `response` (the image's size) with its maximum; for
// tests and tools.
Status CornerResponse(const ConstGrayView& image, const CornerConfig& config,
                      FilterScratch& scratch, ImageView<float> response,
                      float* max_strength = nullptr);

// Strength of an ideal right-angle corner of unit contrast at unit sigma: the maximum over the
// plane of |N| for I = Phi(x) Phi(y), evaluated numerically; it scales Corner2D::strength.
inline constexpr double kIdealCornerResponse = 0.0299739;

}  // namespace sh
