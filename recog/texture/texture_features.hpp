// Local texture features of one image: scale- and rotation-invariant interest points with a
// SIFT-type descriptor (Azad, Asfour & Dillmann 2007, section V.A; Lowe 2004 for the descriptor).
//
// Interest points are Harris corners found on every level of a Gaussian pyramid whose levels
// shrink by kPyramidStep; a point's scale is the level's size factor, its orientation the peak
// of a gradient-orientation histogram around it. The descriptor is Lowe's 4 x 4 cells x 8
// orientations of gradient energy over a 16 x 16 level-pixel window turned to the point's
// orientation, normalised, clipped at 0.2, renormalised and stored as bytes (x 512, at most 255).
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/vector.hpp"
#include "tables/texture_records.hpp"

namespace sh::texture {

// Level k of the pyramid has kPyramidStep^k of the input's resolution (at most
// kMaxPyramidLevels levels, tables/texture_records.hpp).
inline constexpr float kPyramidStep = 0.75f;

// Most interest points per image (orientations counted separately). When more pass the
// threshold, the strongest of each level are kept (level budgets in proportion to level area).
inline constexpr size_t kMaxTextureKeypoints = 1536;

// The descriptor's cells and orientations: tables/texture_records.hpp (TextureDescriptor).
inline constexpr int kDescriptorCellPx = 4;  // level pixels per cell side
inline constexpr int kDescriptorWindowPx = kDescriptorCells * kDescriptorCellPx;

struct TextureKeypoint {
  float x_px = 0.0f;  // input-image pixel (level-0 coordinates)
  float y_px = 0.0f;
  float angle_rad = 0.0f;  // dominant gradient direction in image axes (x right, y down), (-pi, pi]
  float scale = 1.0f;      // input pixels per level pixel: kPyramidStep^-level
  float response = 0.0f;   // Harris response at the level (intensities on [0, 1])
  uint8_t level = 0;
};

struct TextureFeatureStats {
  uint32_t levels = 0;              // pyramid levels used
  uint32_t maxima_found = 0;        // Harris maxima above the threshold, all levels
  uint32_t maxima_dropped = 0;      // of those, beyond the level budgets
  uint32_t extra_orientations = 0;  // keypoints added for secondary orientation peaks
};

// Keypoints and descriptors in the same order.
struct TextureFeatures {
  Vector<TextureKeypoint, kMaxTextureKeypoints> keypoints;
  Vector<TextureDescriptor, kMaxTextureKeypoints> descriptors;
  TextureFeatureStats stats;

  void clear() {
    keypoints.clear();
    descriptors.clear();
    stats = {};
  }
};

}  // namespace sh::texture
