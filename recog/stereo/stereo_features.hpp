// The 2-D image features that stereo consumes, in this module's own minimal form so that stereo
// does not depend on the detectors' internals; the pipeline copies detector output into these.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

namespace sh {

// Most features per image accepted by one stereo call. FeatureSource stores 16-bit indices, and
// the matcher's static workspace is sized by these.
// They equal the detectors' capacities (kMaxCorners2d, kMaxLines2d, kMaxSegmentsPerLine in
// recog/image), checked by static_assert in image_adapters.hpp.
inline constexpr size_t kMaxStereoCorners = 1024;
inline constexpr size_t kMaxStereoLines = 512;
// Edge-supported segments kept per line; a detector reporting more must drop the shortest.
inline constexpr size_t kMaxStereoLineSegments = 16;

// A corner in distorted pixel coordinates (as detected, not rectified).
struct StereoPoint2D {
  float x_px = 0.0f;
  float y_px = 0.0f;
  float strength = 0.0f;  // detector response; ScenePoint::quality is the smaller of the two
};

// End points of a piece of a line that edge pixels support, in distorted pixels.
struct StereoSegment2D {
  float x0_px = 0.0f;
  float y0_px = 0.0f;
  float x1_px = 0.0f;
  float y1_px = 0.0f;
};

// An infinite 2-D line with the segments of it that edge pixels support.
struct StereoLine2D {
  Eigen::Vector2f point_px = Eigen::Vector2f::Zero();    // any point on the line
  Eigen::Vector2f direction = Eigen::Vector2f::UnitX();  // unit direction
  uint8_t segment_count = 0;                             // <= kMaxStereoLineSegments
  StereoSegment2D segments[kMaxStereoLineSegments];
};

}  // namespace sh
