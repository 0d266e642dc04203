// Orientation assignment and the SIFT-type descriptor of one interest point, computed from the
// gradient planes of the pyramid level the point was found on (coordinates in level pixels).
#pragma once

#include "recog/texture/float_planes.hpp"
#include "recog/texture/texture_features.hpp"

namespace sh::texture {

inline constexpr int kOrientationBins = 36;
// Most orientations reported for one point (the main peak and secondary peaks).
inline constexpr int kMaxPointOrientations = 4;

struct OrientationConfig {
  float sigma_px = 2.5f;         // Gaussian window of the histogram, level pixels
  float secondary_ratio = 0.8f;  // peaks of at least this fraction of the highest also count
  int max_orientations = 2;      // 1 .. kMaxPointOrientations
};

// Gaussian window of the orientation histogram, tabulated once per configuration.
inline constexpr int kMaxOrientationRadius = 18;  // 3 sigma for sigma up to 6 px
struct OrientationWindow {
  int radius = 0;
  float weight[2 * kMaxOrientationRadius + 1][2 * kMaxOrientationRadius + 1] = {};  // 0 outside
};
void MakeOrientationWindow(const OrientationConfig& config, OrientationWindow* window);

// Dominant gradient orientations around (x, y): the peaks of a 36-bin histogram of gradient
// directions weighted by magnitude and the Gaussian window, smoothed, with the peak positions
// interpolated by a parabola. Writes up to config.max_orientations angles in (-pi, pi], highest
// peak first; returns how many (0 when there is no gradient at all).
int DominantOrientations(const ConstFloatView& gx, const ConstFloatView& gy, float x, float y,
                         const OrientationConfig& config, const OrientationWindow& window,
                         float* angles_rad);

// Descriptor of the point at (x, y), at least DescriptorBorderPx() inside the planes, with
// orientation angle_rad: gradients sampled bilinearly on a 16 x 16 grid turned by angle_rad (one
// sample per level pixel), rotated into the point's frame, weighted by a Gaussian of sigma half the
// window, and spread trilinearly over 4 x 4 cells x 8 orientations; then Lowe's normalisation (unit
// length, clip at 0.2, unit length) and bytes (x 512, at most 255).
void ComputeDescriptor(const ConstFloatView& gx, const ConstFloatView& gy, float x, float y,
                       float angle_rad, TextureDescriptor* out);

// Level pixels a point must keep from the border for its descriptor window (turned by any
// angle) to lie inside the level.
int DescriptorBorderPx();

// atan2 with an absolute error below 1e-4 rad, for binning gradient directions; 0 at (0, 0).
// Branch-free, so that the loops over gradients of the descriptor and the orientation
// histogram, which inline it, vectorise.
float FastAtan2(float y, float x);

}  // namespace sh::texture
