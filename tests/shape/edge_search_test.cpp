// The edge search along a sample's normal: the same edge as a plain scan over every transition
// from s = -range, which reads every class and colour, on images with silhouettes, shading and
// noise, near and beyond the image's border.
#include "recog/shape/edge_search.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace sh {
namespace {

constexpr uint8_t kPart = 3;

// Two discs of the part's class on a darker table; the part shaded across, everything noisy, and
// the discs' rims blended over a pixel, as a rendered outline is.
struct TestImage {
  static constexpr int kWidth = 96, kHeight = 72;
  static constexpr size_t kPixels = size_t{kWidth} * kHeight;
  std::vector<Rgb8> rgb = std::vector<Rgb8>(kPixels);
  std::vector<uint8_t> classes = std::vector<uint8_t>(kPixels);

  TestImage() {
    std::mt19937 rng(11);
    std::normal_distribution<float> noise(0.0f, 3.0f);
    const float discs[2][3] = {{30, 30, 20}, {66, 44, 17}};  // centre x, y, radius (px)
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        float cover = 0.0f;  // of the pixel by a disc, over a one-pixel blend
        for (const auto& d : discs) {
          const float r = std::hypot(x - d[0], y - d[1]);
          cover = std::max(cover, std::min(1.0f, std::max(0.0f, d[2] + 0.5f - r)));
        }
        const float part[3] = {60.0f + 1.5f * x, 150.0f - 0.8f * y, 40.0f + 0.5f * (x + y)};
        const float table[3] = {35, 38, 36};
        uint8_t c[3];
        for (int k = 0; k < 3; ++k) {
          const float v = cover * part[k] + (1.0f - cover) * table[k] + noise(rng);
          c[k] = static_cast<uint8_t>(std::lround(std::min(255.0f, std::max(0.0f, v))));
        }
        const size_t i = static_cast<size_t>(y) * kWidth + x;
        rgb[i] = {c[0], c[1], c[2]};
        classes[i] = cover > 0.6f ? kPart : 1;
      }
    }
  }
  ImageView<const Rgb8> rgb_view() const { return {rgb.data(), kWidth, kHeight, kWidth}; }
  ConstGrayView class_view() const { return {classes.data(), kWidth, kHeight, kWidth}; }
};

float Distance(const float* a, const float* b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

// Every sample read, every transition tested in order of s, the nearest edge kept.
bool ScanEdge(ImageView<const Rgb8> image, ConstGrayView classes, uint8_t colour, bool silhouette,
              const Eigen::Vector2f& p, const Eigen::Vector2f& n, int range, float min_contrast,
              float* s_out) {
  const int count = 2 * range + 3;
  std::vector<std::array<float, 3>> c(count);
  std::vector<bool> valid(count), inside(count);
  for (int i = 0; i < count; ++i) {
    const float s = static_cast<float>(i - range - 1);
    const float x = p.x() + s * n.x(), y = p.y() + s * n.y();
    valid[i] = SampleRgb(image, x, y, c[i].data());
    inside[i] = valid[i] && classes.at(static_cast<int>(std::lround(x)),
                                       static_cast<int>(std::lround(y))) == colour;
  }
  const auto outside = [&](int i) { return valid[i] && !inside[i]; };
  const auto g = [&](int i) {
    if (i < 0 || i + 1 >= count || !valid[i] || !valid[i + 1]) return 0.0f;
    return Distance(c[i].data(), c[i + 1].data());
  };
  bool found = false;
  for (int i = 1; i <= 2 * range; ++i) {
    int peak = i;
    if (silhouette) {
      if (!inside[i] || !outside(i + 1) || outside(i - 1) || inside[i + 2]) continue;
      for (const int j : {i - 1, i + 1}) {
        if (g(j) > g(peak)) peak = j;
      }
      if (peak == 0 || peak + 1 >= count) continue;
    } else if (!inside[i] || !inside[i + 1] || g(i) < g(i - 1) || g(i) < g(i + 1)) {
      continue;
    }
    if (g(peak) < min_contrast) continue;
    float offset = 0.0f;  // of the parabola's peak
    const float a = g(peak - 1), b = g(peak), d = g(peak + 1);
    if (a - 2.0f * b + d < 0.0f) {
      offset = std::max(-0.5f, std::min(0.5f, 0.5f * (a - d) / (a - 2.0f * b + d)));
    }
    const float s = static_cast<float>(peak - range) - 0.5f + offset;
    if (!found || std::fabs(s) < std::fabs(*s_out)) *s_out = s;
    found = true;
  }
  return found;
}

TEST(EdgeSearch, FindsTheEdgeAPlainScanFinds) {
  const TestImage image;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> x(-4.0f, TestImage::kWidth + 3.0f);
  std::uniform_real_distribution<float> y(-4.0f, TestImage::kHeight + 3.0f);
  std::uniform_real_distribution<float> angle(0.0f, 6.2831853f);
  std::uniform_int_distribution<int> range(1, kMaxEdgeSearchPx);
  int found[2] = {0, 0}, trials[2] = {0, 0}, nearer_than_range = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const bool silhouette = trial % 2 == 0;
    const Eigen::Vector2f p(x(rng), y(rng));
    const float a = angle(rng);
    const Eigen::Vector2f n(std::cos(a), std::sin(a));
    const int r = trial % 3 == 0 ? range(rng) : 1 + trial % 12;  // mostly the ranges used
    const float min_contrast = silhouette ? 20.0f : 6.0f;
    float s = 0.0f, s_scan = 0.0f;
    const bool hit = SearchEdge(image.rgb_view(), image.class_view(), kPart, silhouette, p, n, r,
                                min_contrast, &s);
    const bool hit_scan = ScanEdge(image.rgb_view(), image.class_view(), kPart, silhouette, p, n, r,
                                   min_contrast, &s_scan);
    ++trials[silhouette];
    ASSERT_EQ(hit, hit_scan) << "trial " << trial << " at (" << p.x() << ", " << p.y() << ")";
    if (!hit) continue;
    ++found[silhouette];
    ASSERT_NEAR(s, s_scan, 1e-4f) << "trial " << trial;
    nearer_than_range += std::fabs(s) < r ? 1 : 0;
  }
  // Both kinds of edge are there to find, often enough for the comparison to mean something.
  EXPECT_GT(found[1], trials[1] / 10);
  EXPECT_GT(found[0], trials[0] / 10);
  EXPECT_GT(nearer_than_range, (found[0] + found[1]) / 2);
}

TEST(EdgeSearch, RefusesRangesAndClassImagesItCannotSearch) {
  const TestImage image;
  const Eigen::Vector2f p(10.0f, 30.0f), n(1.0f, 0.0f);  // across the first disc's left rim
  float s = 0.0f;
  ASSERT_TRUE(SearchEdge(image.rgb_view(), image.class_view(), kPart, true, p, -n, 6, 20.0f, &s));
  EXPECT_NEAR(s, 0.0f, 1.0f);
  EXPECT_FALSE(SearchEdge(image.rgb_view(), image.class_view(), kPart, true, p, -n, 0, 20.0f, &s));
  EXPECT_FALSE(SearchEdge(image.rgb_view(), image.class_view(), kPart, true, p, -n,
                          kMaxEdgeSearchPx + 1, 20.0f, &s));
  ConstGrayView smaller = image.class_view();
  smaller.height -= 1;
  EXPECT_FALSE(SearchEdge(image.rgb_view(), smaller, kPart, true, p, -n, 6, 20.0f, &s));
}

}  // namespace
}  // namespace sh
