// Frame views: Y'CbCr conversion against the floating-point definitions of BT.601 and BT.709,
// plane checks, and the grey path reading the luma plane in place.
#include "recog/image/frame.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace sh {
namespace {

// R'G'B' of a Y'CbCr triple by the standard's formulas, in double.
void Reference(double kr, double kb, bool limited, int y, int cb, int cr, double rgb[3]) {
  const double kg = 1.0 - kr - kb;
  const double Y = limited ? (y - 16) * 255.0 / 219.0 : y;
  const double Cb = (cb - 128) * (limited ? 255.0 / 224.0 : 1.0);
  const double Cr = (cr - 128) * (limited ? 255.0 / 224.0 : 1.0);
  rgb[0] = Y + 2.0 * (1.0 - kr) * Cr;
  rgb[1] = Y - 2.0 * kb * (1.0 - kb) / kg * Cb - 2.0 * kr * (1.0 - kr) / kg * Cr;
  rgb[2] = Y + 2.0 * (1.0 - kb) * Cb;
  for (int k = 0; k < 3; ++k) rgb[k] = std::min(255.0, std::max(0.0, rgb[k]));
}

struct OnePixelNv12 {
  uint8_t y;
  CbCr8 c;
  FrameView frame(YcbcrEncoding e, YcbcrRange r) const {
    return FrameView::Nv12({&y, 1, 1, 1}, {&c, 1, 1, 1}, e, r);
  }
};

TEST(Frame, YcbcrConversionMatchesTheStandardsWithinOneCode) {
  struct Case {
    YcbcrEncoding e;
    YcbcrRange r;
    double kr, kb;
  };
  const Case cases[] = {{YcbcrEncoding::kRec601, YcbcrRange::kFull, 0.299, 0.114},
                        {YcbcrEncoding::kRec601, YcbcrRange::kLimited, 0.299, 0.114},
                        {YcbcrEncoding::kRec709, YcbcrRange::kFull, 0.2126, 0.0722},
                        {YcbcrEncoding::kRec709, YcbcrRange::kLimited, 0.2126, 0.0722}};
  for (const Case& c : cases) {
    double worst = 0;
    for (int y = 0; y < 256; y += 5) {
      for (int cb = 0; cb < 256; cb += 15) {
        for (int cr = 0; cr < 256; cr += 15) {
          OnePixelNv12 p{static_cast<uint8_t>(y),
                         {static_cast<uint8_t>(cb), static_cast<uint8_t>(cr)}};
          Rgb8 out;
          FrameRowToRgb(p.frame(c.e, c.r), 0, &out);
          double ref[3];
          Reference(c.kr, c.kb, c.r == YcbcrRange::kLimited, y, cb, cr, ref);
          worst = std::max({worst, std::fabs(out.r - ref[0]), std::fabs(out.g - ref[1]),
                            std::fabs(out.b - ref[2])});
        }
      }
    }
    EXPECT_LE(worst, 1.0) << static_cast<int>(c.e) << " " << static_cast<int>(c.r);
  }
}

TEST(Frame, LimitedRangeEndsMapToBlackAndWhite) {
  for (auto [y, want] : {std::pair{16, 0}, {235, 255}}) {
    OnePixelNv12 p{static_cast<uint8_t>(y), {128, 128}};
    Rgb8 out;
    FrameRowToRgb(p.frame(YcbcrEncoding::kRec601, YcbcrRange::kLimited), 0, &out);
    EXPECT_EQ(out.r, want);
    EXPECT_EQ(out.g, want);
    EXPECT_EQ(out.b, want);
  }
}

// A 4 x 2 frame in NV12 and I420 with the same samples converts identically, each pixel taking
// the chroma of its 2 x 2 block.
TEST(Frame, Nv12AndI420AgreeAndShareChromaPerBlock) {
  const uint8_t y[8] = {10, 60, 110, 160, 20, 70, 120, 170};
  const CbCr8 cbcr[2] = {{90, 200}, {180, 60}};
  const uint8_t cb[2] = {90, 180}, cr[2] = {200, 60};
  const FrameView nv12 =
      FrameView::Nv12({y, 4, 2, 4}, {cbcr, 2, 1, 2}, YcbcrEncoding::kRec601, YcbcrRange::kFull);
  const FrameView i420 = FrameView::Yuv420({y, 4, 2, 4}, {cb, 2, 1, 2}, {cr, 2, 1, 2},
                                           YcbcrEncoding::kRec601, YcbcrRange::kFull);
  ASSERT_TRUE(CheckFrame(nv12).ok());
  ASSERT_TRUE(CheckFrame(i420).ok());
  for (int row = 0; row < 2; ++row) {
    Rgb8 a[4], b[4];
    FrameRowToRgb(nv12, row, a);
    FrameRowToRgb(i420, row, b);
    for (int x = 0; x < 4; ++x) {
      EXPECT_EQ(a[x].r, b[x].r);
      EXPECT_EQ(a[x].g, b[x].g);
      EXPECT_EQ(a[x].b, b[x].b);
      OnePixelNv12 single{y[row * 4 + x], cbcr[x / 2]};
      Rgb8 s;
      FrameRowToRgb(single.frame(YcbcrEncoding::kRec601, YcbcrRange::kFull), 0, &s);
      EXPECT_EQ(a[x].r, s.r);
      EXPECT_EQ(a[x].b, s.b);
    }
  }
}

TEST(Frame, CheckFrameNamesMissingOrMisSizedPlanes) {
  const uint8_t y[12] = {};
  const CbCr8 c[4] = {};
  // 3 x 4 luma needs 2 x 2 chroma.
  EXPECT_TRUE(CheckFrame(FrameView::Nv12({y, 3, 4, 3}, {c, 2, 2, 2}, YcbcrEncoding::kRec601,
                                         YcbcrRange::kFull))
                  .ok());
  const Status wrong = CheckFrame(
      FrameView::Nv12({y, 3, 4, 3}, {c, 1, 2, 1}, YcbcrEncoding::kRec601, YcbcrRange::kFull));
  EXPECT_EQ(wrong.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(wrong.message()).find("NV12"), std::string::npos);
  EXPECT_FALSE(CheckFrame(FrameView::Nv12({y, 3, 4, 3}, {nullptr, 2, 2, 2}, YcbcrEncoding::kRec601,
                                          YcbcrRange::kFull))
                   .ok());
  EXPECT_FALSE(CheckFrame(FrameView::Gray({y, 3, 4, 2})).ok());  // stride < width
  EXPECT_FALSE(CheckFrame(FrameView::Gray({nullptr, 0, 0, 0})).ok());
  EXPECT_FALSE(CheckFrame(FrameView::Rgb({nullptr, 3, 4, 3})).ok());
}

TEST(Frame, GreyPathReadsTheLumaPlaneInPlace) {
  std::vector<uint8_t> y(16 * 8, 7);
  std::vector<CbCr8> c(8 * 4);
  const FrameView nv12 = FrameView::Nv12({y.data(), 16, 8, 16}, {c.data(), 8, 4, 8},
                                         YcbcrEncoding::kRec709, YcbcrRange::kLimited);
  ConstGrayView luma;
  ASSERT_TRUE(FrameLuma(nv12, &luma));
  EXPECT_EQ(luma.data, y.data());  // no copy
  std::vector<Rgb8> rgb(4);
  EXPECT_FALSE(FrameLuma(FrameView::Rgb({rgb.data(), 2, 2, 2}), &luma));
}

TEST(Frame, RgbToGreyUsesTheDecodersBt601Weights) {
  const Rgb8 px[3] = {{255, 0, 0}, {0, 255, 0}, {10, 20, 250}};
  uint8_t grey[3];
  ASSERT_TRUE(FrameToGray(FrameView::Rgb({px, 3, 1, 3}), {grey, 3, 1, 3}).ok());
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(grey[i], (77u * px[i].r + 150u * px[i].g + 29u * px[i].b + 128u) >> 8);
  }
  uint8_t small[2];
  EXPECT_FALSE(FrameToGray(FrameView::Rgb({px, 3, 1, 3}), {small, 2, 1, 2}).ok());
}

}  // namespace
}  // namespace sh
