// The one-dimensional edge search of the colour path's refinement (shape_refine.hpp): along the
// image normal of a projected model edge, the image edge nearest the prediction.
//
// Samples lie at p + s n for whole s in [-range - 1, range + 1], one pixel apart; sample i is at
// s = i - range - 1 and the transition between samples i and i + 1 at s = i - range - 0.5.
//   - Silhouette: the part's colour class on samples i - 1 (where it exists) and i, another
//     class on i + 1 and i + 2 (where they exist). The edge is the colour gradient's peak among
//     the transitions i - 1, i and i + 1 (the classes switch where a blended pixel stops
//     looking like the part, which for a dark background is well past the middle of the blend).
//   - Crease: the part's class on both sides, and a gradient that is a local maximum.
// The peak must reach min_contrast (R'G'B' distance per pixel), and is located to a fraction
// of a pixel by a parabola through it and its neighbours. Of the edges found, the nearest s = 0
// is returned; of two equally near, the one of the lower transition (as a scan from s = -range
// keeps it).
//
// Classes are read at the nearest pixel of the segmentation's class image, colours are
// interpolated bilinearly and only where a gradient is needed.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "recog/image/image.hpp"

namespace sh {

// The widest search (range, pixels either side of the prediction): its samples' classes fit
// in the bits of one 64-bit word (2 range + 3 <= 64).
inline constexpr int kMaxEdgeSearchPx = 30;

// The edge along p + s n (n of unit length, |s| <= range + 1.5) nearest s = 0, as above: true
// and *s_out set when there is one. range must lie in 1..kMaxEdgeSearchPx, and the class image
// must have the colour image's size (false otherwise).
bool SearchEdge(ImageView<const Rgb8> image, ConstGrayView classes, uint8_t colour, bool silhouette,
                const Eigen::Vector2f& p, const Eigen::Vector2f& n, int range, float min_contrast,
                float* s_out);

// Sub-pixel R'G'B' of an image at (x, y) (bilinear; pixel centres at integer coordinates).
// False outside [0, w - 1] x [0, h - 1].
bool SampleRgb(ImageView<const Rgb8> image, float x, float y, float rgb[3]);

}  // namespace sh
