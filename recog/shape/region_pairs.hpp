// Stereo correspondence of colour regions (seed 001 section IV-A): a left and a right region
// may show the same part when they have the same colour class, the right centroid lies near the
// epipolar line of the left centroid, their triangulated centroid lies in front of both cameras
// within the working depth range, and their sizes agree.
//
// Centroids of the two views of one part differ by more than feature positions do (the cameras
// see different sides; occlusion differs), so the epipolar tolerance grows with the region's
// size. Every pair within the gates is a candidate, cheapest first; the recogniser's
// verification decides which are real.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/shape/segmentation.hpp"

namespace sh {

inline constexpr size_t kMaxRegionPairs = 256;

struct RegionPairConfig {
  float epipolar_base_px = 4.0f;      // tolerance for a point-like region
  float epipolar_size_share = 0.25f;  // plus this share of the region's larger box side
  float max_area_ratio = 2.5f;        // right / left area and its inverse
  float min_depth_mm = 100.0f;        // triangulated centroid depth (left camera z)
  float max_depth_mm = 3000.0f;
};

Status CheckRegionPairConfig(const RegionPairConfig& config);

struct RegionPair {
  uint16_t left = 0, right = 0;  // indices into the two segmentations' regions
  float epipolar_px = 0;         // distance of the right centroid from the epipolar line
  float cost = 0;                // epipolar_px / tolerance + |log(area ratio)|
  Eigen::Vector3f centroid_mm = Eigen::Vector3f::Zero();  // triangulated, left camera frame
};

// All pairs within the gates, sorted by cost. `truncated` when more than fit (the cheapest are
// kept).
Status PairRegions(const StereoCalibration& calib, const Vector<ColourRegion>& left,
                   const Vector<ColourRegion>& right, const RegionPairConfig& config,
                   Vector<RegionPair>& out, bool* truncated);

}  // namespace sh
