// The size-normalised window: eq. 1 of seed 001, unit energy, and what it is for: the same
// shape at two sizes gives nearly the same window, different shapes do not.
#include "recog/shape/shape_window.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

namespace sh {
namespace {

struct Mask {
  int w, h;
  std::vector<uint8_t> px;
  ConstGrayView view() const { return {px.data(), w, h, w}; }
};

// An ellipse with semi-axes a, b (pixels) filling its bounding box.
Mask Ellipse(float a, float b) {
  Mask m{static_cast<int>(std::ceil(2 * a)), static_cast<int>(std::ceil(2 * b)), {}};
  m.px.assign(static_cast<size_t>(m.w) * m.h, 0);
  for (int y = 0; y < m.h; ++y) {
    for (int x = 0; x < m.w; ++x) {
      const float u = (x + 0.5f - m.w * 0.5f) / a, v = (y + 0.5f - m.h * 0.5f) / b;
      if (u * u + v * v <= 1.0f) m.px[y * m.w + x] = 255;
    }
  }
  return m;
}

// An axis-aligned L: a bar of width t on the left and a foot of height t at the bottom.
Mask LShape(int w, int h, int t) {
  Mask m{w, h, std::vector<uint8_t>(static_cast<size_t>(w) * h, 0)};
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (x < t || y >= h - t) m.px[y * w + x] = 255;
    }
  }
  return m;
}

float Distance(const ShapeWindow& a, const ShapeWindow& b) {
  double d2 = 0;
  for (int i = 0; i < kWindowPixels; ++i) d2 += double(a.v[i] - b.v[i]) * (a.v[i] - b.v[i]);
  return static_cast<float>(std::sqrt(d2));
}

class ShapeWindowTest : public ::testing::Test {
 protected:
  ShapeWindow Window(const Mask& m) {
    ShapeWindow w;
    const Status s = ComputeShapeWindow(m.view(), *scratch_, &w);
    EXPECT_TRUE(s.ok()) << s.message();
    return w;
  }
  std::unique_ptr<ShapeWindowScratch> scratch_ = std::make_unique<ShapeWindowScratch>();
};

TEST(NormalisedSize, EquationOne) {
  int w0, h0;
  NormalisedSize(100, 50, 64, &w0, &h0);
  EXPECT_EQ(w0, 64);
  EXPECT_EQ(h0, 32);
  NormalisedSize(50, 100, 64, &w0, &h0);
  EXPECT_EQ(w0, 32);
  EXPECT_EQ(h0, 64);
  NormalisedSize(90, 61, 64, &w0, &h0);  // 64 * 61 / 90 = 43.38
  EXPECT_EQ(h0, 43);
  NormalisedSize(90, 62, 64, &w0, &h0);  // 44.09
  EXPECT_EQ(h0, 44);
  NormalisedSize(77, 77, 64, &w0, &h0);
  EXPECT_EQ(w0, 64);
  EXPECT_EQ(h0, 64);
  NormalisedSize(300, 1, 64, &w0, &h0);  // never zero
  EXPECT_EQ(h0, 1);
}

TEST_F(ShapeWindowTest, WindowHasUnitEnergyAndKeepsTheShapesSymmetry) {
  const ShapeWindow w = Window(Ellipse(40, 25));
  double e = 0;
  for (float v : w.v) e += double(v) * v;
  EXPECT_NEAR(e, 1.0, 1e-5);
  // Mirror symmetric about the window's vertical centre line (the 64 x 40 block is centred).
  float worst = 0;
  for (int y = 0; y < kWindowSide; ++y) {
    for (int x = 0; x < kWindowSide; ++x) {
      worst = std::max(worst, std::fabs(w.v[y * kWindowSide + x] -
                                        w.v[y * kWindowSide + (kWindowSide - 1 - x)]));
    }
  }
  EXPECT_LT(worst, 1e-4f);
}

TEST_F(ShapeWindowTest, SameShapeAtTwoSizesMatchesAndOtherShapesDoNot) {
  const ShapeWindow small_l = Window(LShape(45, 60, 12));
  const ShapeWindow large_l = Window(LShape(135, 180, 36));
  const ShapeWindow ellipse = Window(Ellipse(22.5f, 30));
  const ShapeWindow thin_l = Window(LShape(45, 60, 5));
  const float same = Distance(small_l, large_l);
  EXPECT_LT(same, 0.15f);
  EXPECT_GT(Distance(small_l, ellipse), 4 * same);
  EXPECT_GT(Distance(small_l, thin_l), 2 * same);
}

TEST_F(ShapeWindowTest, EmptyOrOversizedMasksAreRefused) {
  Mask zero{10, 10, std::vector<uint8_t>(100, 0)};
  ShapeWindow w;
  EXPECT_EQ(ComputeShapeWindow(zero.view(), *scratch_, &w).code(), StatusCode::kInvalidArgument);
  EXPECT_FALSE(ComputeShapeWindow({nullptr, 0, 0, 0}, *scratch_, &w).ok());
  std::vector<uint8_t> big(static_cast<size_t>(kMaxImageWidth + 1) * 2, 255);
  EXPECT_EQ(
      ComputeShapeWindow({big.data(), kMaxImageWidth + 1, 2, kMaxImageWidth + 1}, *scratch_, &w)
          .code(),
      StatusCode::kOutOfRange);
}

}  // namespace
}  // namespace sh
