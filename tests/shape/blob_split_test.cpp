// Mask parts: components, the neck split (two touching discs come apart, a disc with a thin arm
// does not), the opening that drops thin parts, and refusals.
#include "recog/shape/blob_split.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

namespace sh {
namespace {

struct Mask {
  int w, h;
  std::vector<uint8_t> px;
  Mask(int width, int height) : w(width), h(height), px(static_cast<size_t>(width) * height) {}
  void Disc(float cx, float cy, float r) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (std::hypot(x - cx, y - cy) <= r) px[static_cast<size_t>(y) * w + x] = 255;
      }
    }
  }
  void Box(int x0, int y0, int x1, int y1) {  // inclusive
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) px[static_cast<size_t>(y) * w + x] = 255;
    }
  }
  ConstGrayView view() const { return {px.data(), w, h, w}; }
};

class MaskPartsTest : public ::testing::Test {
 protected:
  std::unique_ptr<MaskPartsScratch> scratch_ = std::make_unique<MaskPartsScratch>();
  MaskPart parts_[kMaxMaskParts];
};

TEST_F(MaskPartsTest, TwoDiscsJoinedByANarrowNeckComeApartOnlyWhenSplitting) {
  Mask m(120, 60);
  m.Disc(30, 30, 20);
  m.Disc(90, 30, 20);
  m.Box(45, 28, 75, 31);  // a 4 px neck, a fifth of the discs' inscribed radius
  std::vector<uint8_t> labels(m.px.size());
  const GrayView out{labels.data(), m.w, m.h, m.w};
  Result<int> whole = MaskParts(m.view(), false, 0.6f, 50, *scratch_, out, parts_);
  ASSERT_TRUE(whole.ok()) << whole.status().message();
  EXPECT_EQ(*whole, 1);
  Result<int> split = MaskParts(m.view(), true, 0.6f, 50, *scratch_, out, parts_);
  ASSERT_TRUE(split.ok()) << split.status().message();
  ASSERT_EQ(*split, 2);
  // Each part holds one disc's centre, near its centroid; every inside pixel is labelled.
  const float disc_area = 3.14159f * 20 * 20;
  uint32_t labelled = 0, inside = 0;
  for (size_t i = 0; i < labels.size(); ++i) {
    labelled += labels[i] != 0;
    inside += m.px[i] != 0;
  }
  EXPECT_EQ(labelled, inside);
  EXPECT_NE(labels[30 * m.w + 30], labels[30 * m.w + 90]);
  for (int k = 0; k < 2; ++k) {
    const float cx = parts_[k].cx < 60 ? 30.0f : 90.0f;
    EXPECT_NEAR(parts_[k].cx, cx, 6.0f);
    EXPECT_NEAR(parts_[k].cy, 30.0f, 1.0f);
    EXPECT_GT(parts_[k].area_px, 0.9f * disc_area);
    EXPECT_LT(parts_[k].area_px, 1.2f * disc_area);
  }
}

TEST_F(MaskPartsTest, ADiscWithAThinArmStaysWhole) {
  Mask m(120, 60);
  m.Disc(30, 30, 20);
  m.Box(45, 28, 115, 31);  // an arm with no distance peak of its own
  std::vector<uint8_t> labels(m.px.size());
  Result<int> n =
      MaskParts(m.view(), true, 0.6f, 50, *scratch_, {labels.data(), m.w, m.h, m.w}, parts_);
  ASSERT_TRUE(n.ok()) << n.status().message();
  EXPECT_EQ(*n, 1);
}

TEST_F(MaskPartsTest, SeparateComponentsUnderTheMinimumAreaAreDropped) {
  Mask m(100, 40);
  m.Disc(20, 20, 15);
  m.Disc(60, 20, 10);
  m.Box(90, 5, 93, 8);  // 16 pixels
  std::vector<uint8_t> labels(m.px.size());
  Result<int> n =
      MaskParts(m.view(), false, 0.0f, 50, *scratch_, {labels.data(), m.w, m.h, m.w}, parts_);
  ASSERT_TRUE(n.ok()) << n.status().message();
  EXPECT_EQ(*n, 2);
  EXPECT_EQ(labels[6 * m.w + 91], 0);
  EXPECT_EQ(parts_[0].x0 + parts_[1].x0, 5 + 50);  // the two discs' boxes, in either order
}

TEST_F(MaskPartsTest, OpeningDropsThinPartsAndKeepsTheThickOne) {
  Mask m(120, 60);
  m.Disc(30, 30, 20);
  m.Box(45, 28, 115, 31);
  std::vector<uint8_t> opened(m.px.size());
  Result<uint32_t> kept = OpenMask(m.view(), 0.6f, *scratch_, {opened.data(), m.w, m.h, m.w});
  ASSERT_TRUE(kept.ok()) << kept.status().message();
  EXPECT_EQ(opened[30 * m.w + 30], 255);  // the disc's centre
  EXPECT_EQ(opened[30 * m.w + 100], 0);   // the arm, far from the disc
  const float disc_area = 3.14159f * 20 * 20;
  EXPECT_GT(*kept, 0.8f * disc_area);
  EXPECT_LT(*kept, 1.05f * disc_area);
  for (size_t i = 0; i < opened.size(); ++i) {
    if (opened[i]) {
      EXPECT_NE(m.px[i], 0) << "opening added pixel " << i;
    }
  }
}

TEST_F(MaskPartsTest, RefusesMismatchedOutputsAndOversizedMasks) {
  Mask m(40, 40);
  m.Disc(20, 20, 10);
  std::vector<uint8_t> labels(m.px.size());
  EXPECT_EQ(MaskParts(m.view(), true, 0.6f, 1, *scratch_, {labels.data(), 39, 40, 39}, parts_)
                .status()
                .code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(OpenMask(m.view(), 0.6f, *scratch_, {labels.data(), 40, 39, 40}).status().code(),
            StatusCode::kInvalidArgument);
  Mask big(600, 600);
  big.Disc(300, 300, 100);
  std::vector<uint8_t> big_labels(big.px.size());
  EXPECT_EQ(MaskParts(big.view(), true, 0.6f, 1, *scratch_,
                      {big_labels.data(), big.w, big.h, big.w}, parts_)
                .status()
                .code(),
            StatusCode::kOutOfRange);
}

}  // namespace
}  // namespace sh
