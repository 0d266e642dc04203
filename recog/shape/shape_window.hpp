// The size-normalised window of a segmented region (seed 001 section IV-B): the region's mask is
// resized into a k x k window keeping its aspect ratio (eq. 1), its gradient magnitude taken,
// and the result normalised to unit energy (sum of squares 1), so that the match does not
// depend on the region's size in the image or on a constant factor.
//
// Resizing is an exact box filter (each window pixel is the mask's mean over the source area it
// covers), so a region seen at any distance gives nearly the same window; a [1 2 1] blur before
// the gradient widens the outline to three pixels, which tolerates the pixel steps of a
// segmentation. The database builder and the recogniser both call ComputeShapeWindow: the views
// and the scene regions go through the very same arithmetic.
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/image/image.hpp"
#include "tables/shape_views_format.hpp"

namespace sh {

// k of eq. 1: the side the view database stores its windows at.
inline constexpr int kWindowSide = kShapeViewWindowSide;
inline constexpr int kWindowPixels = kShapeViewWindowPixels;

// Eq. 1: (k, floor(k h / w + 0.5)) when w >= h, else (floor(k w / h + 0.5), k); at least 1.
void NormalisedSize(int w, int h, int k, int* w0, int* h0);

struct ShapeWindow {
  float v[kWindowPixels];  // row-major, unit energy
};

// Scratch of the resize (one column of partial sums per source row).
struct ShapeWindowScratch {
  float rows[kMaxImageHeight][kWindowSide];
  uint32_t prefix[kMaxImageWidth + 1];
};

// `mask`: 0 outside, 255 inside (other values weigh proportionally); its w x h pixels are the
// region's bounding box. Errors: empty or oversized mask, or a mask with no pixel set.
Status ComputeShapeWindow(ConstGrayView mask, ShapeWindowScratch& scratch, ShapeWindow* out);

}  // namespace sh
