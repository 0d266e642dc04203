// Connected colour regions: areas, boxes, centroids and runs of drawn shapes, 8-connectivity,
// the size filter, the capacities, and the same regions from RGB and NV12 frames.
#include "recog/shape/segmentation.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

namespace sh {
namespace {

constexpr Rgb8 kRed{200, 60, 50}, kBlue{60, 90, 200}, kTable{30, 30, 30};

struct Canvas {
  int w, h;
  std::vector<Rgb8> px;
  Canvas(int w_, int h_) : w(w_), h(h_), px(static_cast<size_t>(w_) * h_, kTable) {}
  void Rect(int x0, int y0, int x1, int y1, Rgb8 c) {  // inclusive
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) px[y * w + x] = c;
    }
  }
  FrameView frame() const { return FrameView::Rgb({px.data(), w, h, w}); }
};

class SegmentationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const float kd[2][3] = {{0.8f, 0.12f, 0.1f}, {0.12f, 0.25f, 0.8f}};
    ColourClassSet set;
    uint8_t cls[2];
    ASSERT_TRUE(DeriveColourClasses(kd, 2, &set, cls).ok());
    red_ = cls[0];
    blue_ = cls[1];
    ASSERT_TRUE(classifier_.Init(set).ok());
  }
  const ColourRegion* Find(uint8_t colour, int x, int y) const {
    for (const ColourRegion& r : seg_->regions()) {
      if (r.colour == colour && x >= r.x0 && x <= r.x1 && y >= r.y0 && y <= r.y1) return &r;
    }
    return nullptr;
  }
  ColourClassifier classifier_;
  std::unique_ptr<ColourSegmentation> seg_ = std::make_unique<ColourSegmentation>();
  uint8_t red_ = 0, blue_ = 0;
};

TEST_F(SegmentationTest, RectanglesAndAnLShapeGiveTheirAreasBoxesAndCentroids) {
  Canvas c(120, 80);
  c.Rect(10, 10, 29, 19, kRed);   // 20 x 10
  c.Rect(50, 5, 59, 44, kBlue);   // L: 10 x 40 vertical bar ...
  c.Rect(60, 35, 89, 44, kBlue);  // ... and 30 x 10 foot
  c.Rect(30, 20, 34, 24, kBlue);  // 5 x 5, diagonal neighbour of the red one, other colour
  SegmentConfig config;
  config.min_area_px = 20;
  ASSERT_TRUE(seg_->Segment(c.frame(), classifier_, config).ok());
  ASSERT_EQ(seg_->regions().size(), 3u);
  const ColourRegion* red = Find(red_, 15, 15);
  ASSERT_NE(red, nullptr);
  EXPECT_EQ(red->area_px, 200u);
  EXPECT_EQ(red->x0, 10);
  EXPECT_EQ(red->x1, 29);
  EXPECT_EQ(red->y0, 10);
  EXPECT_EQ(red->y1, 19);
  EXPECT_FLOAT_EQ(red->cx, 19.5f);
  EXPECT_FLOAT_EQ(red->cy, 14.5f);
  EXPECT_EQ(red->n_runs, 10u);
  const ColourRegion* l = Find(blue_, 55, 10);
  ASSERT_NE(l, nullptr);
  EXPECT_EQ(l->area_px, 400u + 300u);
  EXPECT_EQ(l->width(), 40);
  EXPECT_EQ(l->height(), 40);
  // Centroid of the L: area-weighted mean of the two rectangles.
  EXPECT_NEAR(l->cx, (400 * 54.5 + 300 * 74.5) / 700.0, 1e-4);
  EXPECT_NEAR(l->cy, (400 * 24.5 + 300 * 39.5) / 700.0, 1e-4);
  // Runs, chained in scan order, rebuild the mask.
  std::vector<uint8_t> mask(static_cast<size_t>(l->width()) * l->height());
  RegionMask(*l, seg_->runs(), {mask.data(), l->width(), l->height(), l->width()});
  int set = 0;
  for (uint8_t m : mask) set += m == 255;
  EXPECT_EQ(set, 700);
  EXPECT_EQ(mask[0], 255);                                                // top of the bar
  EXPECT_EQ(mask[l->width() - 1], 0);                                     // above the foot
  EXPECT_EQ(mask[(l->height() - 1) * l->width() + l->width() - 1], 255);  // end of the foot
  // The class image keeps every pixel's class.
  EXPECT_EQ(seg_->classes().at(15, 15), red_);
  EXPECT_EQ(seg_->classes().at(0, 0), kNoColourClass);
}

TEST_F(SegmentationTest, DiagonalNeighboursJoinAndSmallRegionsAreDropped) {
  Canvas c(40, 40);
  c.Rect(5, 5, 14, 14, kRed);
  c.Rect(15, 15, 24, 24, kRed);  // touches the first at a corner only
  c.Rect(30, 30, 32, 32, kRed);  // 9 pixels
  SegmentConfig config;
  config.min_area_px = 10;
  ASSERT_TRUE(seg_->Segment(c.frame(), classifier_, config).ok());
  ASSERT_EQ(seg_->regions().size(), 1u);
  EXPECT_EQ(seg_->regions()[0].area_px, 200u);
}

TEST_F(SegmentationTest, NoiseBeyondTheRunCapacityIsReportedNotOverrun) {
  // A checkerboard of single pixels: every coloured pixel is its own run.
  Canvas c(1280, 60);
  for (int y = 0; y < c.h; ++y) {
    for (int x = (y & 1); x < c.w; x += 2) c.px[y * c.w + x] = kRed;
  }
  ASSERT_TRUE(seg_->Segment(c.frame(), classifier_, SegmentConfig{}).ok());
  EXPECT_TRUE(seg_->runs_truncated());
  EXPECT_LE(seg_->runs().size(), kMaxColourRuns);
  // The class image is complete even where runs were not labelled.
  EXPECT_EQ(seg_->classes().at(1, c.h - 1), red_);
}

TEST_F(SegmentationTest, MoreRegionsThanFitKeepTheLargest) {
  Canvas c(1200, 40);
  const int n = static_cast<int>(kMaxColourRegions) + 10;
  for (int i = 0; i < n; ++i) c.Rect(i * 12, 5, i * 12 + (i < 10 ? 5 : 7), 10, kRed);
  ASSERT_TRUE(seg_->Segment(c.frame(), classifier_, SegmentConfig{1}).ok());
  EXPECT_TRUE(seg_->regions_truncated());
  ASSERT_EQ(seg_->regions().size(), kMaxColourRegions);
  for (const ColourRegion& r : seg_->regions()) EXPECT_EQ(r.width(), 8);  // 6-wide ones dropped
}

TEST_F(SegmentationTest, Nv12FramesGiveTheRegionsOfTheirRgbEquivalent) {
  // Blocks of 2 x 2 pixels share chroma in NV12: draw on even coordinates.
  const int w = 64, h = 48;
  std::vector<uint8_t> y(static_cast<size_t>(w) * h, 30);
  std::vector<CbCr8> cbcr(static_cast<size_t>(w / 2) * (h / 2), CbCr8{128, 128});
  // Full-range BT.601 of the red (200, 60, 50): Y 101, Cb 99, Cr 199 (rounded).
  for (int yy = 10; yy < 30; ++yy) {
    for (int xx = 20; xx < 44; ++xx) y[yy * w + xx] = 101;
  }
  for (int yy = 5; yy < 15; ++yy) {
    for (int xx = 10; xx < 22; ++xx) cbcr[yy * (w / 2) + xx] = {99, 199};
  }
  const FrameView frame = FrameView::Nv12({y.data(), w, h, w}, {cbcr.data(), w / 2, h / 2, w / 2},
                                          YcbcrEncoding::kRec601, YcbcrRange::kFull);
  ASSERT_TRUE(seg_->Segment(frame, classifier_, SegmentConfig{20}).ok());
  ASSERT_EQ(seg_->regions().size(), 1u);
  const ColourRegion& r = seg_->regions()[0];
  EXPECT_EQ(r.colour, red_);
  EXPECT_EQ(r.area_px, 20u * 24u);
  EXPECT_FLOAT_EQ(r.cx, 31.5f);
  EXPECT_FLOAT_EQ(r.cy, 19.5f);
}

TEST_F(SegmentationTest, GreyFramesHaveNoColourRegionsAndBadInputIsRefused) {
  std::vector<uint8_t> grey(100 * 50, 200);
  ASSERT_TRUE(
      seg_->Segment(FrameView::Gray({grey.data(), 100, 50, 100}), classifier_, SegmentConfig{})
          .ok());
  EXPECT_TRUE(seg_->regions().empty());
  EXPECT_FALSE(
      seg_->Segment(FrameView::Gray({nullptr, 0, 0, 0}), classifier_, SegmentConfig{}).ok());
  EXPECT_FALSE(
      seg_->Segment(FrameView::Gray({grey.data(), 100, 50, 100}), classifier_, SegmentConfig{0})
          .ok());
}

}  // namespace
}  // namespace sh
