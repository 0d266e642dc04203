// Copies the detectors' output (recog/image) into stereo's input structs. Header-only, so that
// stereohash_stereo itself does not link the image library.
#pragma once

#include <cstddef>

#include "recog/base/vector.hpp"
#include "recog/image/corners.hpp"
#include "recog/image/hough.hpp"
#include "recog/stereo/stereo_features.hpp"

namespace sh {

static_assert(kMaxStereoCorners >= kMaxCorners2d, "stereo must take every detected corner");
static_assert(kMaxStereoLines >= kMaxLines2d, "stereo must take every detected line");
static_assert(kMaxStereoLineSegments >= kMaxSegmentsPerLine,
              "stereo must take every segment of a line");

// Writes corners.size() entries to out (capacity at least kMaxStereoCorners); returns the count.
inline size_t ToStereoPoints(const Vector<Corner2D>& corners, StereoPoint2D* out) {
  for (size_t i = 0; i < corners.size(); ++i) {
    out[i] = {corners[i].x_px, corners[i].y_px, corners[i].strength};
  }
  return corners.size();
}

inline StereoLine2D ToStereoLine(const Line2D& line) {
  StereoLine2D out;
  out.point_px = Eigen::Vector2f(line.point_x_px, line.point_y_px);
  out.direction = Eigen::Vector2f(line.dir_x, line.dir_y).normalized();
  out.segment_count = static_cast<uint8_t>(line.segments.size());
  for (size_t k = 0; k < line.segments.size(); ++k) {
    const Segment2D& s = line.segments[k];
    out.segments[k] = {s.x0, s.y0, s.x1, s.y1};
  }
  return out;
}

// Writes lines.size() entries to out (capacity at least kMaxStereoLines); returns the count.
inline size_t ToStereoLines(const Vector<Line2D>& lines, StereoLine2D* out) {
  for (size_t i = 0; i < lines.size(); ++i) out[i] = ToStereoLine(lines[i]);
  return lines.size();
}

}  // namespace sh
