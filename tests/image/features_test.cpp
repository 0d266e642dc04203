#include "recog/image/features.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "tests/support/synthetic_image.hpp"

namespace sh {
namespace {

using testing::Point2;
using testing::Polygon;

// Both presets find every vertex and side of the scene they are meant for.
void CheckPreset(const FeatureConfig& config, double background, double object) {
  const int w = 756, h = 581;
  const std::vector<Polygon> polys = testing::TestScene(w, h, object);
  testing::SyntheticImage synth(w, h, background);
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
  testing::SyntheticImage synth(kMaxImageWidth, kMaxImageHeight, 0);
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
