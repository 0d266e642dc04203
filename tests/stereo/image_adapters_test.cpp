#include "recog/stereo/image_adapters.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace sh {
namespace {

TEST(ImageAdapters, CornersKeepPositionAndStrength) {
  Vector<Corner2D, 4> corners;
  ASSERT_TRUE(corners.push_back({10.5f, 20.25f, 0.3f}));
  ASSERT_TRUE(corners.push_back({-1.0f, 7.0f, 0.9f}));
  StereoPoint2D out[4];
  ASSERT_EQ(ToStereoPoints(corners, out), 2u);
  EXPECT_EQ(out[1].x_px, -1.0f);
  EXPECT_EQ(out[0].y_px, 20.25f);
  EXPECT_EQ(out[1].strength, 0.9f);
}

TEST(ImageAdapters, LineKeepsGeometryAndEverySegment) {
  auto line = std::make_unique<Line2D>();
  const float theta = 0.7f, rho = 150.0f;
  line->theta_rad = theta;
  line->rho_px = rho;
  line->dir_x = std::cos(theta);
  line->dir_y = -std::sin(theta);
  line->point_x_px = rho * std::sin(theta);
  line->point_y_px = rho * std::cos(theta);
  for (size_t k = 0; k < kMaxSegmentsPerLine; ++k) {
    const float t0 = 10.0f * k, t1 = t0 + 5.0f;
    ASSERT_TRUE(line->segments.push_back(
        {line->point_x_px + t0 * line->dir_x, line->point_y_px + t0 * line->dir_y,
         line->point_x_px + t1 * line->dir_x, line->point_y_px + t1 * line->dir_y}));
  }
  const StereoLine2D s = ToStereoLine(*line);
  ASSERT_EQ(s.segment_count, kMaxSegmentsPerLine);
  EXPECT_NEAR(s.direction.norm(), 1.0f, 1e-6f);
  // The stereo line is the same infinite line: every segment end lies on it.
  for (size_t k = 0; k < s.segment_count; ++k) {
    EXPECT_NEAR(line->DistancePx(s.segments[k].x0_px, s.segments[k].y0_px), 0.0f, 1e-3f);
    EXPECT_NEAR(line->DistancePx(s.segments[k].x1_px, s.segments[k].y1_px), 0.0f, 1e-3f);
  }
  EXPECT_NEAR(line->DistancePx(s.point_px.x() + 100.0f * s.direction.x(),
                               s.point_px.y() + 100.0f * s.direction.y()),
              0.0f, 1e-3f);
}

}  // namespace
}  // namespace sh
