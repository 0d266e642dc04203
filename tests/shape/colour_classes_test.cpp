// Colour classes derived from model colours, and the per-pixel classifier, on pixel values as
// the recorded colour scenes show them (sRGB-encoded, shaded, with highlights and a table that
// mirrors the parts faintly).
#include "recog/shape/colour_classes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace sh {
namespace {

// The eight colour models' Kd (models/colour/*.mtl), in file-name order.
constexpr float kKd[8][3] = {
    {0.15f, 0.65f, 0.20f},  // bracket (green)
    {0.80f, 0.12f, 0.10f},  // can (red)
    {0.80f, 0.12f, 0.10f},  // cube (red)
    {0.15f, 0.65f, 0.20f},  // hexagon (green)
    {0.12f, 0.25f, 0.80f},  // pentagon (blue)
    {0.90f, 0.80f, 0.10f},  // star (yellow)
    {0.90f, 0.80f, 0.10f},  // trapezium (yellow)
    {0.12f, 0.25f, 0.80f},  // wedge (blue)
};

ColourClassSet ModelClasses(uint8_t* class_of_model) {
  ColourClassSet set;
  EXPECT_TRUE(DeriveColourClasses(kKd, 8, &set, class_of_model).ok());
  return set;
}

TEST(Hsv, KnownColours) {
  Hsv h = RgbToHsv(255, 0, 0);
  EXPECT_FLOAT_EQ(h.h_deg, 0);
  EXPECT_FLOAT_EQ(h.s, 1);
  h = RgbToHsv(0, 0.5f, 0);
  EXPECT_FLOAT_EQ(h.h_deg, 120);
  EXPECT_FLOAT_EQ(h.v, 0.5f);
  h = RgbToHsv(0.2f, 0.2f, 0.8f);
  EXPECT_FLOAT_EQ(h.h_deg, 240);
  EXPECT_FLOAT_EQ(h.s, 0.75f);
  h = RgbToHsv(1, 0, 1);
  EXPECT_FLOAT_EQ(h.h_deg, 300);
  EXPECT_FLOAT_EQ(RgbToHsv(3, 3, 3).s, 0);
  EXPECT_FLOAT_EQ(HueDistanceDeg(350, 10), 20);
  EXPECT_FLOAT_EQ(HueDistanceDeg(10, 190), 180);
}

TEST(ColourClasses, SharedColoursShareAClassAndTolerancesFollowTheHueGaps) {
  uint8_t cls[8];
  const ColourClassSet set = ModelClasses(cls);
  ASSERT_EQ(set.n_classes, 4);
  EXPECT_EQ(cls[0], cls[3]);  // bracket, hexagon
  EXPECT_EQ(cls[1], cls[2]);  // can, cube
  EXPECT_EQ(cls[4], cls[7]);  // pentagon, wedge
  EXPECT_EQ(cls[5], cls[6]);  // star, trapezium
  EXPECT_NE(cls[0], cls[1]);
  EXPECT_NE(cls[1], cls[5]);
  // Red (1.7 deg) and yellow (52.5 deg) are the closest pair: each gets 45 % of their gap.
  const ColourClass& red = set.classes[cls[1] - 1];
  const ColourClass& yellow = set.classes[cls[5] - 1];
  const float gap = HueDistanceDeg(red.hue_deg, yellow.hue_deg);
  EXPECT_NEAR(red.hue_tolerance_deg, kHueShareOfGap * gap, 1e-3f);
  EXPECT_NEAR(yellow.hue_tolerance_deg, kHueShareOfGap * gap, 1e-3f);
  EXPECT_FLOAT_EQ(set.classes[cls[4] - 1].hue_tolerance_deg, kMaxHueToleranceDeg);  // blue
  EXPECT_NEAR(red.min_saturation, kMinSaturationFraction * 0.875f, 1e-3f);
}

TEST(ColourClasses, GreyColoursAndTooManyColoursAreRefused) {
  const float grey[1][3] = {{0.5f, 0.5f, 0.45f}};
  ColourClassSet set;
  uint8_t cls[16];
  Status s = DeriveColourClasses(grey, 1, &set, cls);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("saturation"), std::string::npos);
  float many[9][3];
  for (int i = 0; i < 9; ++i) {
    const float a = 2.0f * 3.14159265f * i / 9.0f;  // nine hues 40 degrees apart
    many[i][0] = 0.5f + 0.45f * std::cos(a);
    many[i][1] = 0.5f + 0.45f * std::cos(a - 2.0944f);
    many[i][2] = 0.5f + 0.45f * std::cos(a + 2.0944f);
  }
  s = DeriveColourClasses(many, 9, &set, cls);
  EXPECT_EQ(s.code(), StatusCode::kResourceExhausted);
  const float bad[1][3] = {{1.5f, 0.0f, 0.0f}};
  EXPECT_FALSE(DeriveColourClasses(bad, 1, &set, cls).ok());
}

TEST(ColourClassifier, ScenePixelsGoToTheirPartsAndTheTableToNone) {
  uint8_t cls[8];
  const ColourClassSet set = ModelClasses(cls);
  ColourClassifier classifier;
  ASSERT_TRUE(classifier.Init(set).ok());
  const uint8_t red = cls[1], green = cls[0], blue = cls[4], yellow = cls[5];
  struct Pixel {
    Rgb8 p;
    uint8_t want;
  };
  // Values read from ../shared/scenes/colour (lit faces, shaded faces, highlights, tables).
  const Pixel pixels[] = {
      {{182, 73, 68}, red},
      {{211, 86, 81}, red},
      {{202, 89, 81}, red},
      {{86, 167, 101}, green},
      {{92, 184, 106}, green},
      {{83, 172, 101}, green},
      {{72, 111, 186}, blue},
      {{51, 77, 136}, blue},
      {{251, 246, 128}, yellow},
      {{192, 182, 65}, yellow},
      {{171, 163, 61}, yellow},
      {{238, 229, 93}, yellow},
      {{27, 27, 24}, kNoColourClass},
      {{22, 21, 22}, kNoColourClass},
      {{185, 186, 180}, kNoColourClass},  // light table
      {{184, 181, 175}, kNoColourClass},  // mirror image of a red part on the light table
      {{145, 147, 141}, kNoColourClass},  // shadow on the light table
      {{22, 33, 56}, blue},               // a blue face in deep shade
  };
  for (const Pixel& px : pixels) {
    EXPECT_EQ(classifier.Classify(px.p), px.want)
        << int(px.p.r) << " " << int(px.p.g) << " " << int(px.p.b);
    EXPECT_EQ(ColourClassifier::ClassifyExact(set, px.p.r, px.p.g, px.p.b), px.want);
  }
}

TEST(ColourClassifier, TableAgreesWithTheRuleExceptNearItsThresholds) {
  uint8_t cls[8];
  const ColourClassSet set = ModelClasses(cls);
  ColourClassifier classifier;
  ASSERT_TRUE(classifier.Init(set).ok());
  std::mt19937 rng(3);
  int disagree = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Rgb8 p{static_cast<uint8_t>(rng()), static_cast<uint8_t>(rng()),
                 static_cast<uint8_t>(rng())};
    disagree += classifier.Classify(p) != ColourClassifier::ClassifyExact(set, p.r, p.g, p.b);
  }
  // The table quantises to 8 code values per channel: only pixels within a cell of a threshold
  // can differ.
  EXPECT_LT(disagree, n / 20);
}

}  // namespace
}  // namespace sh
