#include "recog/image/noise.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "recog/image/features.hpp"

namespace sh {
namespace {

// A table-like image: a slow brightness ramp (lamp fall-off), two polygons of other grey levels
// (objects with edges and corners), and Gaussian noise of the given sigma, rounded to 8 bits.
std::vector<uint8_t> SceneLikeImage(int w, int h, float sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  std::vector<uint8_t> img(size_t(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float v = 90.0f + 40.0f * x / w + 20.0f * y / h;
      if (x > w / 4 && x < w / 2 && y > h / 4 && y < h / 2) v = 180.0f;
      if (x + y > w && x - y < w / 3) v = 40.0f;
      v += sigma * noise(rng);
      img[size_t(y) * w + x] = static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L));
    }
  }
  return img;
}

TEST(Noise, EstimatesTheSigmaOfAddedNoise) {
  const int w = 400, h = 300;
  for (float sigma : {1.0f, 2.0f, 4.0f, 8.0f}) {
    const std::vector<uint8_t> img = SceneLikeImage(w, h, sigma, 11);
    const NoiseEstimate e = EstimateNoise(ConstGrayView{img.data(), w, h, w});
    // The estimate includes the rounding to 8 bits (variance 1/12): compare with the total.
    const float expected = std::sqrt(sigma * sigma + 1.0f / 12.0f);
    EXPECT_NEAR(e.sigma, expected, 0.1f * expected) << "sigma " << sigma;
    EXPECT_GT(e.samples, size_t(w * h / 5));
  }
}

TEST(Noise, EdgesAndRampsAloneAreNotNoise) {
  const int w = 400, h = 300;
  const std::vector<uint8_t> clean = SceneLikeImage(w, h, 0.0f, 1);
  EXPECT_LT(EstimateNoise(ConstGrayView{clean.data(), w, h, w}).sigma, 0.15f);
}

TEST(Noise, TinyOrEmptyImagesGiveZero) {
  const uint8_t px[4] = {1, 200, 3, 90};
  EXPECT_EQ(EstimateNoise(ConstGrayView{px, 2, 2, 2}).samples, 0u);
  EXPECT_EQ(EstimateNoise(ConstGrayView{}).sigma, 0.0f);
}

// The adaptive detector follows the noise: thresholds rise with it, and a noisier image of the
// same scene yields no flood of spurious corners and edge pixels.
TEST(Noise, AdaptiveThresholdsFollowTheNoise) {
  const int w = 400, h = 300;
  FeatureConfig config = FeatureConfig::LightBackground();
  config.adaptive = true;
  DetectionChoice quiet, loud;
  FeatureConfig effective;
  const std::vector<uint8_t> a = SceneLikeImage(w, h, 1.0f, 3);
  const std::vector<uint8_t> b = SceneLikeImage(w, h, 6.0f, 3);
  ASSERT_TRUE(ChooseDetection(ConstGrayView{a.data(), w, h, w}, config, &effective, &quiet).ok());
  ASSERT_TRUE(ChooseDetection(ConstGrayView{b.data(), w, h, w}, config, &effective, &loud).ok());
  EXPECT_TRUE(quiet.adaptive);
  EXPECT_GT(loud.noise_sigma, 4.0f * quiet.noise_sigma);
  EXPECT_GT(loud.canny_low, 3.0f * quiet.canny_low);
  EXPECT_NEAR(loud.canny_high, config.canny_high_ratio * loud.canny_low, 1e-4f);
  EXPECT_GT(loud.corner_threshold, quiet.corner_threshold);
  // The floors hold on a noise-free image.
  const std::vector<uint8_t> clean = SceneLikeImage(w, h, 0.0f, 3);
  DetectionChoice none;
  ASSERT_TRUE(
      ChooseDetection(ConstGrayView{clean.data(), w, h, w}, config, &effective, &none).ok());
  EXPECT_FLOAT_EQ(none.canny_low, config.canny_low_floor);
  const float c = config.corner_min_contrast / 255.0f;
  EXPECT_NEAR(none.corner_threshold, c * c * c, 1e-9f);

  // Same scene, both noise levels: the edge pixels found stay of the same order.
  static FeatureWorkspace workspace;
  ASSERT_TRUE(workspace.Init(w, h).ok());
  static ImageFeatures fa, fb;
  ASSERT_TRUE(ExtractFeatures(ConstGrayView{a.data(), w, h, w}, config, workspace, fa).ok());
  ASSERT_TRUE(ExtractFeatures(ConstGrayView{b.data(), w, h, w}, config, workspace, fb).ok());
  EXPECT_GT(fa.canny_stats.edge_pixels, 500u);
  EXPECT_LT(fb.canny_stats.edge_pixels, 2 * fa.canny_stats.edge_pixels);
  EXPECT_LT(fb.corners.size(), 4 * std::max<size_t>(fa.corners.size(), 4));
  EXPECT_EQ(fa.chosen.canny_low, quiet.canny_low);

  // Bad factors are refused with a message.
  FeatureConfig bad = config;
  bad.canny_high_ratio = 0.5f;
  EXPECT_FALSE(ChooseDetection(ConstGrayView{a.data(), w, h, w}, bad, &effective, &none).ok());
}

}  // namespace
}  // namespace sh
