#include "recog/image/features.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "tests/image/synthetic_image.hpp"

namespace sh {
namespace {

using test::Point2;
using test::Polygon;

// Both presets find every vertex and side of the scene they are meant for.
void CheckPreset(const FeatureConfig& config, double background, double object) {
  const int w = 756, h = 581;
  const std::vector<Polygon> polys = test::TestScene(w, h, object);
  test::SyntheticImage synth(w, h, background);
  for (const Polygon& p : polys) synth.Fill(p);
  synth.Blur(0.8);
  synth.AddNoise(2.0, 5);
  std::vector<uint8_t> px;
  const ConstGrayView img = synth.ToGray(px);
  auto ws = std::make_unique<FeatureWorkspace>();
  auto features = std::make_unique<ImageFeatures>();
  ASSERT_TRUE(ExtractFeatures(img, config, *ws, *features).ok());
  size_t sides = 0;
  for (const Polygon& p : polys) {
    sides += p.vertices.size();
    for (const Point2& v : p.vertices) {
      double best = 1e9;
      for (const Corner2D& c : features->corners) {
        best = std::min(best, std::hypot(c.x_px - v.x, c.y_px - v.y));
      }
      EXPECT_LT(best, 1.5) << "vertex (" << v.x << ", " << v.y << ")";
    }
  }
  EXPECT_EQ(features->lines.size(), sides);
  EXPECT_EQ(features->edges.edge.width, w);
  EXPECT_EQ(features->canny_stats.edge_pixels, features->hough_stats.edge_pixels);
}

TEST(Features, DarkBackgroundPreset) {
  const FeatureConfig c = FeatureConfig::DarkBackground();
  EXPECT_EQ(c.corners.sigma_px, 6.0f);
  EXPECT_EQ(c.canny.sigma_px, 1.0f);
  ASSERT_TRUE(ValidateFeatureConfig(c).ok());
  CheckPreset(c, 25.0, 200.0);
}

TEST(Features, LightBackgroundPreset) {
  const FeatureConfig c = FeatureConfig::LightBackground();
  EXPECT_EQ(c.corners.sigma_px, 2.0f);
  EXPECT_EQ(c.canny.sigma_px, 2.0f);
  ASSERT_TRUE(ValidateFeatureConfig(c).ok());
  CheckPreset(c, 180.0, 110.0);
}

// With equal corner and Canny scales ExtractFeatures smooths once for both; the corners and the
// edge map are exactly those of the two detectors run on their own.
TEST(Features, SharedSmoothingGivesTheSeparateDetectorsResults) {
  const int w = 756, h = 581;
  test::SyntheticImage synth(w, h, 180.0);
  for (const Polygon& p : test::TestScene(w, h, 110.0)) synth.Fill(p, 4);
  synth.Blur(0.8);
  synth.AddNoise(2.0, 6);
  std::vector<uint8_t> px;
  const ConstGrayView img = synth.ToGray(px);
  const FeatureConfig config = FeatureConfig::LightBackground();
  ASSERT_EQ(config.corners.sigma_px, config.canny.sigma_px);
  ASSERT_TRUE(CornersUseSmoothedImage(config.corners));
  auto ws = std::make_unique<FeatureWorkspace>();
  auto features = std::make_unique<ImageFeatures>();
  ASSERT_TRUE(ExtractFeatures(img, config, *ws, *features).ok());

  auto alone = std::make_unique<FeatureWorkspace>();
  Vector<Corner2D, kMaxCorners2d> corners;
  CornerStats corner_stats;
  ASSERT_TRUE(DetectCorners(img, config.corners, alone->filter, corners, &corner_stats).ok());
  EdgeMapView edges;
  CannyStats canny_stats;
  ASSERT_TRUE(
      DetectEdges(img, config.canny, alone->filter, alone->edges, edges, &canny_stats).ok());

  ASSERT_EQ(features->corners.size(), corners.size());
  ASSERT_GT(corners.size(), 10u);
  for (size_t i = 0; i < corners.size(); ++i) {
    EXPECT_EQ(features->corners[i].x_px, corners[i].x_px) << i;
    EXPECT_EQ(features->corners[i].y_px, corners[i].y_px) << i;
    EXPECT_EQ(features->corners[i].strength, corners[i].strength) << i;
  }
  EXPECT_EQ(features->corner_stats.maxima_found, corner_stats.maxima_found);
  EXPECT_EQ(features->canny_stats.edge_pixels, canny_stats.edge_pixels);
  EXPECT_EQ(features->canny_stats.nms_candidates, canny_stats.nms_candidates);
  ASSERT_GT(canny_stats.edge_pixels, 1000u);
  size_t differing = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      differing += features->edges.edge.at(x, y) != edges.edge.at(x, y) ||
                   features->edges.orientation.at(x, y) != edges.orientation.at(x, y);
    }
  }
  EXPECT_EQ(differing, 0u);
}

TEST(Features, RefusesOversizedAndEmptyImagesWithEmptyOutput) {
  auto ws = std::make_unique<FeatureWorkspace>();
  auto features = std::make_unique<ImageFeatures>();
  std::vector<uint8_t> px(size_t(kMaxImageWidth + 8) * 4, 0);
  const Status s =
      ExtractFeatures(ConstGrayView{px.data(), kMaxImageWidth + 8, 4, kMaxImageWidth + 8},
                      FeatureConfig::DarkBackground(), *ws, *features);
  EXPECT_EQ(s.code(), StatusCode::kOutOfRange);
  EXPECT_TRUE(features->corners.empty());
  EXPECT_TRUE(features->lines.empty());
  EXPECT_TRUE(features->edges.edge.empty());
  EXPECT_EQ(ExtractFeatures(ConstGrayView{}, FeatureConfig{}, *ws, *features).code(),
            StatusCode::kInvalidArgument);
  FeatureConfig bad;
  bad.canny.sigma_px = -1.0f;
  EXPECT_FALSE(ExtractFeatures(ConstGrayView{px.data(), 4, 4, 4}, bad, *ws, *features).ok());
}

TEST(Features, UniformNoiseAtFullSizeStaysWithinCapacity) {
  test::SyntheticImage synth(kMaxImageWidth, kMaxImageHeight, 0);
  synth.FillUniformNoise(9);
  std::vector<uint8_t> px;
  const ConstGrayView img = synth.ToGray(px);
  auto ws = std::make_unique<FeatureWorkspace>();
  auto features = std::make_unique<ImageFeatures>();
  FeatureConfig config = FeatureConfig::LightBackground();
  config.hough.max_peaks = 300;  // bounds the run time of this test
  ASSERT_TRUE(ExtractFeatures(img, config, *ws, *features).ok());
  EXPECT_LE(features->corners.size(), kMaxCorners2d);
  EXPECT_LE(features->lines.size(), kMaxLines2d);
  EXPECT_GT(features->canny_stats.edge_pixels, 0u);
  EXPECT_EQ(features->hough_stats.edge_pixels + features->hough_stats.edge_pixels_dropped,
            features->canny_stats.edge_pixels);
}

}  // namespace
}  // namespace sh
