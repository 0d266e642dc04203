#include "recog/image/features.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
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
  auto ws = MakeWorkspace<FeatureWorkspace>();
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
  auto ws = MakeWorkspace<FeatureWorkspace>();
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
  auto ws = MakeWorkspace<FeatureWorkspace>();
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

// The test scene (its polygons of grey level `intensity` on 40), blurred 0.8 px, with noise of
// sigma 2 (`seed`), as a grey image whose pixels `px` holds.
ConstGrayView NoisySceneImage(int w, int h, double intensity, uint32_t seed,
                              std::vector<uint8_t>& px) {
  const std::vector<Polygon> polys = testing::TestScene(w, h, intensity);
  testing::SyntheticImage synth(w, h, 40.0);
  for (const Polygon& p : polys) synth.Fill(p);
  synth.Blur(0.8);
  synth.AddNoise(2.0, seed);
  return synth.ToGray(px);
}

// The same corners and lines, to the bit, and as many edge pixels.
void ExpectSameFeatures(const ImageFeatures& a, const ImageFeatures& b) {
  ASSERT_EQ(a.corners.size(), b.corners.size());
  ASSERT_EQ(a.lines.size(), b.lines.size());
  EXPECT_EQ(a.canny_stats.edge_pixels, b.canny_stats.edge_pixels);
  for (size_t i = 0; i < a.corners.size(); ++i) {
    EXPECT_EQ(a.corners[i].x_px, b.corners[i].x_px);
    EXPECT_EQ(a.corners[i].y_px, b.corners[i].y_px);
  }
  for (size_t i = 0; i < a.lines.size(); ++i) {
    EXPECT_EQ(a.lines[i].theta_rad, b.lines[i].theta_rad);
    EXPECT_EQ(a.lines[i].rho_px, b.lines[i].rho_px);
    EXPECT_EQ(a.lines[i].edge_pixels, b.lines[i].edge_pixels);
    EXPECT_EQ(a.lines[i].segments.size(), b.lines[i].segments.size());
  }
}

// Buffers sized at Init for the camera: an image of that size gives what a workspace of the
// maximum size gives; a larger one is refused naming both sizes; sizes beyond the maximum and a
// workspace never initialised are refused.
TEST(Features, WorkspaceSizedAtInitForTheCamera) {
  const int w = 320, h = 240;
  std::vector<uint8_t> px;
  const ConstGrayView img = NoisySceneImage(w, h, 200.0, 5, px);
  const FeatureConfig config = FeatureConfig::DarkBackground();

  auto small = MakeWorkspace<FeatureWorkspace>(w, h);
  auto full = MakeWorkspace<FeatureWorkspace>();
  ASSERT_NE(small, nullptr);
  ASSERT_NE(full, nullptr);
  // A 17th of the pixels; Canny's work list (256 KiB at both sizes) and the filter rows do not
  // shrink with the height.
  EXPECT_LT(FeatureWorkspace::BytesFor(w, h), FeatureWorkspace::BytesFor(1280, 1024) / 5);
  auto a = std::make_unique<ImageFeatures>();
  auto b = std::make_unique<ImageFeatures>();
  ASSERT_TRUE(ExtractFeatures(img, config, *small, *a).ok());
  ASSERT_TRUE(ExtractFeatures(img, config, *full, *b).ok());
  ASSERT_GT(a->corners.size(), 0u);
  ExpectSameFeatures(*a, *b);

  // One row more than the workspace holds.
  testing::SyntheticImage taller(w, h + 1, 40.0);
  std::vector<uint8_t> px2;
  const Status st = ExtractFeatures(taller.ToGray(px2), config, *small, *a);
  EXPECT_EQ(st.code(), StatusCode::kOutOfRange);
  EXPECT_NE(std::string(st.message()).find("320x241"), std::string::npos) << st.message();
  EXPECT_NE(std::string(st.message()).find("320x240"), std::string::npos) << st.message();
  EXPECT_EQ(a->corners.size(), 0u);

  FeatureWorkspace ws;
  EXPECT_EQ(ExtractFeatures(img, config, ws, *a).code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(ws.Init(kMaxImageWidth + 1, 800).code(), StatusCode::kOutOfRange);
  EXPECT_EQ(ws.Init(640, 0).code(), StatusCode::kOutOfRange);
  EXPECT_EQ(MakeWorkspace<FeatureWorkspace>(1280, kMaxImageHeight + 1), nullptr);
}

// The Hough transform's pixel lists lie in the filter block (FeatureWorkspace::Init), which the
// filters are done with before the transform: the features are those of a workspace whose parts
// each have a block of their own, and the workspace takes less memory.
TEST(Features, HoughListsInTheFilterBlockGiveTheSameFeatures) {
  const int w = 640, h = 400;
  std::vector<uint8_t> px;
  const ConstGrayView img = NoisySceneImage(w, h, 300.0, 7, px);
  const FeatureConfig config = FeatureConfig::DarkBackground();

  auto shared = MakeWorkspace<FeatureWorkspace>(w, h);
  auto separate = MakeZeroed<FeatureWorkspace>();
  ASSERT_NE(shared, nullptr);
  ASSERT_NE(separate, nullptr);
  ASSERT_TRUE(separate->filter.Init(w, h).ok());
  ASSERT_TRUE(separate->edges.Init(w, h).ok());
  ASSERT_TRUE(separate->hough.Init(w, h).ok());
  const uint8_t* filter_begin = shared->filter.block().data();
  const uint8_t* filter_end = filter_begin + shared->filter.block().bytes();
  const auto* collected = reinterpret_cast<const uint8_t*>(shared->hough.collected);
  const auto* subset =
      reinterpret_cast<const uint8_t*>(shared->hough.subset + shared->hough.point_capacity());
  EXPECT_TRUE(collected >= filter_begin && subset <= filter_end);
  EXPECT_LT(
      FeatureWorkspace::BytesFor(w, h),
      FilterScratch::BytesFor(w, h) + EdgeBuffers::BytesFor(w, h) + HoughWorkspace::BytesFor(w, h));

  auto a = std::make_unique<ImageFeatures>();
  auto b = std::make_unique<ImageFeatures>();
  for (int round = 0; round < 2; ++round) {  // the second frame finds the lists overwritten
    ASSERT_TRUE(ExtractFeatures(img, config, *shared, *a).ok());
    ASSERT_TRUE(ExtractFeatures(img, config, *separate, *b).ok());
    ASSERT_GT(a->lines.size(), 3u);
    ExpectSameFeatures(*a, *b);
    EXPECT_EQ(shared->hough.point_count, separate->hough.point_count);
  }
  // Init again with the same size keeps the blocks and the lists where they were.
  const uint32_t* before = shared->hough.collected;
  ASSERT_TRUE(shared->Init(w, h).ok());
  EXPECT_EQ(shared->hough.collected, before);
  EXPECT_EQ(shared->filter.block().data(), filter_begin);
}

}  // namespace
}  // namespace sh
