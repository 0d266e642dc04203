// The feature extractor and descriptor: invariance to rotation and scale (views rendered from the
// same procedural print), Lowe's normalisation, the atan2 approximation, errors, and no heap.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "recog/texture/descriptor.hpp"
#include "recog/texture/feature_extractor.hpp"
#include "recog/texture/kd_tree.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tests/support/print_images.hpp"

namespace sh::texture {
namespace {

using testing::PrintPattern;
using testing::RenderPattern;
using testing::TestImage;

constexpr float kPi = 3.14159265f;

// A view of the pattern at `px_per_mm`, turned by `angle` about the image centre.
TestImage View(const PrintPattern& p, int size, float px_per_mm, float angle) {
  const float c = std::cos(angle), s = std::sin(angle);
  const float centre = 0.5f * (size - 1);
  return RenderPattern(
      p, size, size,
      [&](float x, float y, Eigen::Vector2f* q) {
        const float dx = x - centre, dy = y - centre;
        // Inverse rotation, then pixels to millimetres around the pattern's centre.
        const float u = c * dx + s * dy, v = -s * dx + c * dy;
        *q =
            Eigen::Vector2f(0.5f * p.size_mm() + u / px_per_mm, 0.5f * p.size_mm() + v / px_per_mm);
        return true;
      },
      1.0f / px_per_mm);
}

struct Extracted {
  std::unique_ptr<TextureFeatures> features = std::make_unique<TextureFeatures>();
};

Extracted Extract(TextureFeatureExtractor& ex, const TestImage& img) {
  Extracted e;
  TextureFeatureConfig config;
  EXPECT_TRUE(ex.Extract(img.view(), config, e.features.get()).ok());
  return e;
}

// Fraction of the first image's keypoints whose nearest descriptor in the second image lies
// where the known mapping puts them (within 2 px at their scale), and the mean orientation
// change of those.
struct MatchStats {
  double correct_fraction = 0;
  double mean_angle_change = 0;
  int correct = 0;
};

template <typename Map>
MatchStats MatchUnder(const TextureFeatures& a, const TextureFeatures& b, Map map_a_to_b) {
  MatchStats st;
  int tried = 0;
  double angle_sum = 0;
  for (size_t i = 0; i < a.keypoints.size(); ++i) {
    const Eigen::Vector2f expected = map_a_to_b(a.keypoints[i].x_px, a.keypoints[i].y_px);
    if (expected.x() < 20 || expected.y() < 20 || expected.x() > 300 || expected.y() > 300)
      continue;
    ++tried;
    uint32_t best = UINT32_MAX;
    size_t best_j = 0;
    for (size_t j = 0; j < b.keypoints.size(); ++j) {
      const uint32_t d = DescriptorDistance2(a.descriptors[i], b.descriptors[j]);
      if (d < best) {
        best = d;
        best_j = j;
      }
    }
    const TextureKeypoint& kb = b.keypoints[best_j];
    if ((Eigen::Vector2f(kb.x_px, kb.y_px) - expected).norm() < 2.0f * std::max(1.0f, kb.scale)) {
      ++st.correct;
      float d = kb.angle_rad - a.keypoints[i].angle_rad;
      while (d > kPi) d -= 2 * kPi;
      while (d <= -kPi) d += 2 * kPi;
      angle_sum += d;
    }
  }
  st.correct_fraction = tried > 0 ? static_cast<double>(st.correct) / tried : 0;
  st.mean_angle_change = st.correct > 0 ? angle_sum / st.correct : 0;
  return st;
}

TEST(TextureFeatures, DescriptorsMatchAcrossARotation) {
  auto ex = std::make_unique<TextureFeatureExtractor>();
  const PrintPattern pattern(120.0f, 60, 7);
  constexpr int kSize = 320;
  constexpr float kAngle = 0.7f;  // 40 degrees
  const TestImage a = View(pattern, kSize, 3.0f, 0.0f);
  const TestImage b = View(pattern, kSize, 3.0f, kAngle);
  const Extracted fa = Extract(*ex, a);
  const Extracted fb = Extract(*ex, b);
  ASSERT_GT(fa.features->keypoints.size(), 100u);
  const float centre = 0.5f * (kSize - 1);
  const float c = std::cos(kAngle), s = std::sin(kAngle);
  const MatchStats st = MatchUnder(*fa.features, *fb.features, [&](float x, float y) {
    const float dx = x - centre, dy = y - centre;
    return Eigen::Vector2f(centre + c * dx - s * dy, centre + s * dx + c * dy);
  });
  EXPECT_GT(st.correct_fraction, 0.6) << st.correct << " correct";
  // Image axes with y down: a turn by +angle maps x to (cos, sin), so orientations grow by it.
  EXPECT_NEAR(st.mean_angle_change, kAngle, 0.05);
}

TEST(TextureFeatures, DescriptorsMatchAcrossAScaleChange) {
  auto ex = std::make_unique<TextureFeatureExtractor>();
  const PrintPattern pattern(120.0f, 60, 11);
  constexpr int kSize = 320;
  const TestImage a = View(pattern, kSize, 3.0f, 0.0f);
  const TestImage b = View(pattern, kSize, 1.8f, 0.0f);  // 0.6 times the size
  const Extracted fa = Extract(*ex, a);
  const Extracted fb = Extract(*ex, b);
  const float centre = 0.5f * (kSize - 1);
  const MatchStats st = MatchUnder(*fa.features, *fb.features, [&](float x, float y) {
    return Eigen::Vector2f(centre + 0.6f * (x - centre), centre + 0.6f * (y - centre));
  });
  EXPECT_GT(st.correct_fraction, 0.35) << st.correct << " correct";
  EXPECT_NEAR(st.mean_angle_change, 0.0, 0.05);
}

TEST(TextureFeatures, DescriptorsAreNormalisedLikeLowe) {
  auto ex = std::make_unique<TextureFeatureExtractor>();
  const TestImage img = View(PrintPattern(100.0f, 50, 3), 256, 3.0f, 0.3f);
  const Extracted f = Extract(*ex, img);
  ASSERT_FALSE(f.features->descriptors.empty());
  for (const TextureDescriptor& d : f.features->descriptors) {
    double sum2 = 0;
    for (uint8_t v : d.v) sum2 += static_cast<double>(v) * v;
    // Unit length times 512, up to the rounding of 128 bytes and the clipping at 255.
    EXPECT_NEAR(std::sqrt(sum2), 512.0, 8.0);
  }
  for (const TextureKeypoint& k : f.features->keypoints) {
    EXPECT_GT(k.angle_rad, -kPi - 1e-5f);
    EXPECT_LE(k.angle_rad, kPi + 1e-5f);
    EXPECT_NEAR(k.scale, std::pow(1.0f / kPyramidStep, static_cast<float>(k.level)), 1e-4f);
  }
}

TEST(TextureFeatures, KeypointsStayOffTheBorderAndWithinTheBudget) {
  auto ex = std::make_unique<TextureFeatureExtractor>();
  const TestImage img = View(PrintPattern(100.0f, 80, 5), 300, 3.0f, 0.0f);
  TextureFeatureConfig config;
  config.max_keypoints = 200;
  auto f = std::make_unique<TextureFeatures>();
  ASSERT_TRUE(ex->Extract(img.view(), config, f.get()).ok());
  // Extra orientations may add a few beyond the candidates the budget admits.
  EXPECT_LE(f->keypoints.size(), 200u * 2);
  EXPECT_GT(f->stats.maxima_dropped, 0u);
  for (const TextureKeypoint& k : f->keypoints) {
    const float border = DescriptorBorderPx() * k.scale;
    EXPECT_GE(k.x_px, border - k.scale);
    EXPECT_GE(k.y_px, border - k.scale);
    EXPECT_LE(k.x_px, 299 - border + k.scale);
    EXPECT_LE(k.y_px, 299 - border + k.scale);
  }
}

TEST(TextureFeatures, ShiTomasiStrengthPeaksAtACornerAndVanishesOnAnEdge) {
  auto ex = std::make_unique<TextureFeatureExtractor>();
  TestImage img(100, 100, 40);
  for (int y = 50; y < 100; ++y) {
    for (int x = 50; x < 100; ++x) img.at(x, y) = 200;  // a quadrant: corner at (49.5, 49.5)
  }
  auto f = std::make_unique<TextureFeatures>();
  ASSERT_TRUE(ex->Extract(img.view(), TextureFeatureConfig{}, f.get()).ok());
  const ConstFloatView m = ex->min_eigenvalue();
  ASSERT_EQ(m.width, 100);
  float peak = 0;
  int px = 0, py = 0;
  for (int y = 0; y < 100; ++y) {
    for (int x = 0; x < 100; ++x) {
      if (m.at(x, y) > peak) {
        peak = m.at(x, y);
        px = x;
        py = y;
      }
    }
  }
  EXPECT_NEAR(px, 50, 2);
  EXPECT_NEAR(py, 50, 2);
  EXPECT_LT(m.at(50, 80), 0.01f * peak);  // on the vertical edge, far from the corner
  EXPECT_LT(m.at(20, 20), 1e-9f);         // flat
}

TEST(TextureFeatures, FastAtan2IsWithinATenthOfAMilliradian) {
  double worst = 0;
  for (int i = -50; i <= 50; ++i) {
    for (int j = -50; j <= 50; ++j) {
      const float y = i * 0.37f, x = j * 0.53f;
      if (i == 0 && j == 0) continue;
      worst =
          std::max(worst, std::fabs(double{FastAtan2(y, x)} - std::atan2(double{y}, double{x})));
    }
  }
  EXPECT_LT(worst, 1e-4);
}

TEST(TextureFeatures, RefusesBadInputWithAReason) {
  auto ex = std::make_unique<TextureFeatureExtractor>();
  auto f = std::make_unique<TextureFeatures>();
  TextureFeatureConfig config;
  EXPECT_EQ(ex->Extract(ConstGrayView{}, config, f.get()).code(), StatusCode::kInvalidArgument);
  std::vector<uint8_t> big(static_cast<size_t>(kMaxImageWidth + 1) * 4, 0);
  EXPECT_EQ(
      ex->Extract({big.data(), kMaxImageWidth + 1, 4, kMaxImageWidth + 1}, config, f.get()).code(),
      StatusCode::kOutOfRange);
  TestImage img(64, 64, 100);
  config.levels = 0;
  EXPECT_EQ(ex->Extract(img.view(), config, f.get()).code(), StatusCode::kOutOfRange);
  config = TextureFeatureConfig{};
  config.input_sigma_px = 2.0f;  // not below the level blur
  EXPECT_EQ(ex->Extract(img.view(), config, f.get()).code(), StatusCode::kOutOfRange);
  EXPECT_TRUE(f->keypoints.empty());
}

TEST(TextureFeatures, ExtractionDoesNotTouchTheHeap) {
  auto ex = std::make_unique<TextureFeatureExtractor>();
  auto f = std::make_unique<TextureFeatures>();
  const TestImage img = View(PrintPattern(100.0f, 40, 9), 256, 3.0f, 0.2f);
  TextureFeatureConfig config;
  ASSERT_TRUE(ex->Extract(img.view(), config, f.get()).ok());  // first use builds tables
  const uint64_t before = testing::HeapAllocations();
  ASSERT_TRUE(ex->Extract(img.view(), config, f.get()).ok());
  EXPECT_EQ(testing::HeapAllocations(), before);
  EXPECT_GT(f->keypoints.size(), 20u);
}

}  // namespace
}  // namespace sh::texture
