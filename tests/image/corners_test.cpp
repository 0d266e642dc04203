#include "recog/image/corners.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <vector>

#include "tests/support/synthetic_image.hpp"

namespace sh {
namespace {

using testing::Point2;
using testing::Polygon;

std::vector<Polygon> SmallScene(double intensity) {
  return {
      {{{40.3, 50.6}, {150.2, 38.1}, {170.7, 140.4}, {55.8, 160.9}}, intensity},  // quadrilateral
      {{{215.4, 60.2}, {300.6, 95.7}, {230.9, 190.3}}, intensity},                // triangle
  };
}

struct Scene {
  std::vector<uint8_t> pixels;
  ConstGrayView view;
  std::vector<Point2> vertices;
};

Scene MakeScene(double background, double object, double noise, uint32_t seed) {
  Scene s;
  testing::SyntheticImage synth(340, 230, background);
  for (const Polygon& p : SmallScene(object)) {
    synth.Fill(p);
    s.vertices.insert(s.vertices.end(), p.vertices.begin(), p.vertices.end());
  }
  synth.Blur(0.7);
  synth.AddNoise(noise, seed);
  s.view = synth.ToGray(s.pixels);
  return s;
}

double NearestCorner(const Vector<Corner2D>& corners, Point2 p) {
  double best = 1e9;
  for (const Corner2D& c : corners) best = std::min(best, std::hypot(c.x_px - p.x, c.y_px - p.y));
  return best;
}

double NearestVertex(const std::vector<Point2>& vertices, const Corner2D& c) {
  double best = 1e9;
  for (const Point2& v : vertices) best = std::min(best, std::hypot(c.x_px - v.x, c.y_px - v.y));
  return best;
}

class CornerScaleTest : public ::testing::TestWithParam<float> {};

TEST_P(CornerScaleTest, FindsEveryVertexAndNothingElse) {
  auto scratch = MakeWorkspace<FilterScratch>();
  for (int run = 0; run < 4; ++run) {
    const bool dark_background = run % 2 == 0;
    const Scene s = dark_background ? MakeScene(30, 200, 2.0, 1) : MakeScene(190, 90, 2.0, 2);
    CornerConfig config;
    config.exact_derivatives = run >= 2;
    config.sigma_px = GetParam();
    config.nms_radius_px = std::max(3, int(config.sigma_px));
    Vector<Corner2D, kMaxCorners2d> corners;
    CornerStats stats;
    ASSERT_TRUE(DetectCorners(s.view, config, *scratch, corners, &stats).ok());
    double worst = 0;
    for (const Point2& v : s.vertices) {
      const double d = NearestCorner(corners, v);
      worst = std::max(worst, d);
      EXPECT_LT(d, 1.0) << "vertex (" << v.x << ", " << v.y << ") sigma_c " << config.sigma_px;
    }
    std::printf("sigma_c %.0f %s background: %zu corners, worst vertex error %.2f px\n",
                double(config.sigma_px), dark_background ? "dark" : "light", corners.size(), worst);
    // Nothing on the straight edges or in the flat regions.
    for (const Corner2D& c : corners) {
      EXPECT_LT(NearestVertex(s.vertices, c), 2.0)
          << "spurious corner at (" << c.x_px << ", " << c.y_px << ") strength " << c.strength;
    }
    for (size_t i = 1; i < corners.size(); ++i) {
      EXPECT_GE(corners[i - 1].strength, corners[i].strength);
    }
    EXPECT_EQ(stats.maxima_dropped, 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(Scales, CornerScaleTest, ::testing::Values(1.5f, 2.0f, 4.0f, 6.0f));

// At a threshold near the noise (the automatic preset's: a corner of contrast 20) the detector
// also reports points along the strong edges, where noise bends the isophotes. Their gradients
// keep to one direction: the isotropy tells them from the vertices.
TEST(Corners, PointsOnStrongEdgesHaveNoIsotropyAndVerticesMuch) {
  auto scratch = MakeWorkspace<FilterScratch>();
  size_t on_edges = 0, isotropic_on_edges = 0, vertices = 0;
  for (uint32_t seed = 1; seed <= 4; ++seed) {
    const Scene s = MakeScene(30, 200, 3.0, seed);
    CornerConfig config;
    config.threshold = std::pow(20.0f / 255.0f, 3.0f);
    Vector<Corner2D, kMaxCorners2d> corners;
    ASSERT_TRUE(DetectCorners(s.view, config, *scratch, corners).ok());
    for (const Corner2D& c : corners) {
      const double d = NearestVertex(s.vertices, c);
      if (d < 2.0) {
        ++vertices;
        EXPECT_GT(c.isotropy, 0.1f) << "vertex at (" << c.x_px << ", " << c.y_px << ")";
      } else if (d > 6.0) {
        ++on_edges;
        isotropic_on_edges += c.isotropy >= 0.008f;
      }
    }
  }
  EXPECT_EQ(vertices, 4u * 7u);
  EXPECT_GE(on_edges, 8u);
  EXPECT_LE(isotropic_on_edges, on_edges / 10);
}

TEST(Corners, WithoutVertexRefinementTheMaximumLiesInsideTheCorner) {
  // The curvature maximum of a blurred corner sits inside the wedge; the refinement removes that.
  auto scratch = MakeWorkspace<FilterScratch>();
  const Scene s = MakeScene(30, 200, 1.0, 3);
  CornerConfig config;
  config.sigma_px = 4.0f;
  config.nms_radius_px = 4;
  Vector<Corner2D, kMaxCorners2d> raw, refined;
  config.refine_to_vertex = false;
  ASSERT_TRUE(DetectCorners(s.view, config, *scratch, raw).ok());
  config.refine_to_vertex = true;
  ASSERT_TRUE(DetectCorners(s.view, config, *scratch, refined).ok());
  double raw_sum = 0, refined_sum = 0;
  for (const Point2& v : s.vertices) {
    raw_sum += NearestCorner(raw, v);
    refined_sum += NearestCorner(refined, v);
  }
  EXPECT_GT(raw_sum / s.vertices.size(), 1.0);
  EXPECT_LT(refined_sum, raw_sum);
}

// The large scales run on the 2x reduced image; the full-resolution difference path at the same
// sigma_c is the reference. On the test scene (756 x 581, four polygons, noise 2) both find the
// same corners (the 19 vertices), every reduced-path corner within 0.35 px of the reference's
// after vertex refinement and within 0.5 px without it, with a strength within 10 %. (At the
// default threshold: the differences on the reduced grid respond to long diagonal edges as the
// full-resolution ones do at sigma_c / 2, up to about 0.011 for a contrast of 170.)
TEST(Corners, ReducedLargeScalesMatchTheFullResolutionReference) {
  auto scratch = MakeWorkspace<FilterScratch>();
  const int w = 756, h = 581;
  for (const bool dark : {true, false}) {
    testing::SyntheticImage synth(w, h, dark ? 30.0 : 190.0);
    for (const Polygon& p : testing::TestScene(w, h, dark ? 200.0 : 90.0)) synth.Fill(p, 4);
    synth.Blur(0.8);
    synth.AddNoise(2.0, dark ? 21 : 22);
    std::vector<uint8_t> px;
    const ConstGrayView img = synth.ToGray(px);
    for (const float sigma : {4.0f, 6.0f}) {
      for (const bool refine : {true, false}) {
        CornerConfig config;
        config.sigma_px = sigma;
        config.nms_radius_px = int(sigma);
        config.refine_to_vertex = refine;
        Vector<Corner2D, kMaxCorners2d> full, reduced;
        config.reduce_large_scales = false;
        ASSERT_TRUE(DetectCorners(img, config, *scratch, full).ok());
        config.reduce_large_scales = true;
        ASSERT_TRUE(DetectCorners(img, config, *scratch, reduced).ok());
        ASSERT_GE(full.size(), 17u);  // the scene's vertices
        EXPECT_EQ(reduced.size(), full.size()) << "sigma_c " << sigma << " refine " << refine;
        const double tolerance = refine ? 0.35 : 0.5;
        double worst = 0;
        for (const Corner2D& f : full) {
          const Corner2D* best = nullptr;
          double d = 1e9;
          for (const Corner2D& r : reduced) {
            const double dr = std::hypot(r.x_px - f.x_px, r.y_px - f.y_px);
            if (dr < d) {
              d = dr;
              best = &r;
            }
          }
          ASSERT_NE(best, nullptr);
          worst = std::max(worst, d);
          EXPECT_LT(d, tolerance) << "(" << f.x_px << ", " << f.y_px << ") sigma_c " << sigma;
          EXPECT_NEAR(best->strength, f.strength, 0.1 * f.strength);
        }
        std::printf(
            "sigma_c %.0f %s, refine %d: %zu corners, worst distance to reference %.2f px\n",
            double(sigma), dark ? "dark" : "light", int(refine), full.size(), worst);
      }
    }
  }
}

TEST(Corners, StrengthScalesWithContrastCubed) {
  auto scratch = MakeWorkspace<FilterScratch>();
  CornerConfig config;
  config.refine_to_vertex = false;
  float strength[2];
  for (int i = 0; i < 2; ++i) {
    testing::SyntheticImage synth(120, 120, 20);
    synth.Fill({{{60, 60}, {200, 60}, {200, 200}, {60, 200}}, 20.0 + (i + 1) * 100.0});
    std::vector<uint8_t> px;
    Vector<Corner2D, kMaxCorners2d> corners;
    ASSERT_TRUE(DetectCorners(synth.ToGray(px), config, *scratch, corners).ok());
    ASSERT_EQ(corners.size(), 1u);
    strength[i] = corners[0].strength;
  }
  EXPECT_NEAR(strength[1] / strength[0], 8.0, 0.2);
  // An ideal right-angle corner of contrast 200 is (200/255)^3 of the unit response; the
  // sampled, pixel-aligned corner is close to the continuous one.
  EXPECT_NEAR(strength[1], std::pow(200.0 / 255.0, 3), 0.1);
}

TEST(Corners, RelativeThresholdKeepsOnlyTheStrongest) {
  auto scratch = MakeWorkspace<FilterScratch>();
  const Scene s = MakeScene(30, 200, 2.0, 4);
  CornerConfig config;
  config.threshold = 0.0f;
  config.relative_threshold = 0.9f;
  Vector<Corner2D, kMaxCorners2d> corners;
  CornerStats stats;
  ASSERT_TRUE(DetectCorners(s.view, config, *scratch, corners, &stats).ok());
  ASSERT_FALSE(corners.empty());
  EXPECT_FLOAT_EQ(stats.threshold_used, 0.9f * stats.max_strength);
  for (const Corner2D& c : corners) EXPECT_GT(c.strength, stats.threshold_used);
}

TEST(Corners, NoiseFillsTheOutputWithTheStrongestMaxima) {
  auto scratch = MakeWorkspace<FilterScratch>();
  testing::SyntheticImage synth(kMaxImageWidth, kMaxImageHeight, 0);
  synth.FillUniformNoise(5);
  std::vector<uint8_t> px;
  const ConstGrayView img = synth.ToGray(px);
  CornerConfig config;
  config.sigma_px = 1.0f;
  config.threshold = 0.0f;
  config.nms_radius_px = 1;
  Vector<Corner2D, kMaxCorners2d> corners;
  CornerStats stats;
  ASSERT_TRUE(DetectCorners(img, config, *scratch, corners, &stats).ok());
  ASSERT_EQ(corners.size(), kMaxCorners2d);
  EXPECT_GT(stats.maxima_found, kMaxCorners2d);
  EXPECT_EQ(stats.maxima_dropped, stats.maxima_found - kMaxCorners2d);
  for (size_t i = 1; i < corners.size(); ++i) {
    EXPECT_GE(corners[i - 1].strength, corners[i].strength);
  }
  for (const Corner2D& c : corners) {
    EXPECT_TRUE(c.x_px >= 0 && c.x_px <= img.width - 1 && c.y_px >= 0 && c.y_px <= img.height - 1);
  }
  // Same input, same output.
  Vector<Corner2D, kMaxCorners2d> again;
  ASSERT_TRUE(DetectCorners(img, config, *scratch, again).ok());
  ASSERT_EQ(again.size(), corners.size());
  for (size_t i = 0; i < corners.size(); ++i) {
    EXPECT_EQ(again[i].x_px, corners[i].x_px);
    EXPECT_EQ(again[i].strength, corners[i].strength);
  }
  // A smaller output keeps the strongest: its weakest is at least the full list's k-th.
  Vector<Corner2D, 16> few;
  ASSERT_TRUE(DetectCorners(img, config, *scratch, few).ok());
  ASSERT_EQ(few.size(), 16u);
  for (size_t i = 0; i < few.size(); ++i) EXPECT_EQ(few[i].strength, corners[i].strength);
}

TEST(Corners, DegenerateImagesAndConfigs) {
  auto scratch = MakeWorkspace<FilterScratch>();
  Vector<Corner2D, kMaxCorners2d> corners;
  std::vector<uint8_t> px(static_cast<size_t>(kMaxImageWidth) * 4, 128);
  CornerConfig config;
  // Flat images of any shape: no corners.
  for (auto [w, h] : {std::pair{1, 1}, {2, 2}, {1, 300}, {300, 1}, {kMaxImageWidth, 4}}) {
    ASSERT_TRUE(DetectCorners(ConstGrayView{px.data(), w, h, w}, config, *scratch, corners).ok());
    EXPECT_TRUE(corners.empty()) << w << "x" << h;
  }
  EXPECT_EQ(DetectCorners(ConstGrayView{}, config, *scratch, corners).code(),
            StatusCode::kInvalidArgument);
  const Status big = DetectCorners(ConstGrayView{px.data(), 10, kMaxImageHeight + 1, 10}, config,
                                   *scratch, corners);
  EXPECT_EQ(big.code(), StatusCode::kOutOfRange);
  EXPECT_NE(std::string(big.message()).find("larger"), std::string::npos) << big.message();
  config.sigma_px = 20.0f;
  EXPECT_EQ(DetectCorners(ConstGrayView{px.data(), 4, 4, 4}, config, *scratch, corners).code(),
            StatusCode::kOutOfRange);
  config = CornerConfig{};
  config.nms_radius_px = 0;
  EXPECT_FALSE(DetectCorners(ConstGrayView{px.data(), 4, 4, 4}, config, *scratch, corners).ok());
  config = CornerConfig{};
  config.threshold = NAN;
  EXPECT_FALSE(DetectCorners(ConstGrayView{px.data(), 4, 4, 4}, config, *scratch, corners).ok());
}

// The response of the row bands against one computed here from whole planes (GaussianFilter2d,
// derivatives in double precision) on an image of the board's size: the smoothed path (central
// differences of the image smoothed at sqrt(sigma^2 - 1/4)) and the exact one (five
// Gaussian-derivative filters). Float sums in another order: agreement to 1e-4 of the maximum.
TEST(CornerBands, ResponseEqualsTheWholePlaneResponse) {
  const int w = 1280, h = 800;
  std::vector<uint8_t> px;
  const ConstGrayView img = testing::NoisyTestScene(w, h, 2.0, 9, px);
  auto scratch = MakeWorkspace<FilterScratch>(w, h);
  ASSERT_NE(scratch, nullptr);
  std::vector<float> tmp(static_cast<size_t>(w) * h), whole(tmp.size());
  std::vector<float> d[5];
  for (std::vector<float>& v : d) v.assign(tmp.size(), 0.0f);
  FloatPlane tmp_plane;
  tmp_plane.data = tmp.data();
  auto plane = [&](int i) { return ImageView<float>{d[i].data(), w, h, w}; };
  for (const bool exact : {false, true}) {
    for (const float sigma : {2.0f, 6.0f, kMaxGaussianSigmaPx}) {
      CornerConfig config;
      config.sigma_px = sigma;
      config.exact_derivatives = exact;
      config.reduce_large_scales = false;
      Vector<Corner2D, kMaxCorners2d> corners;
      CornerStats stats;
      ASSERT_TRUE(DetectCorners(img, config, *scratch, corners, &stats).ok());
      EXPECT_GT(corners.size(), 10u);
      float max_strength = 0.0f;
      ASSERT_TRUE(CornerResponse(img, config, *scratch, ImageView<float>{whole.data(), w, h, w},
                                 &max_strength)
                      .ok());
      EXPECT_EQ(max_strength, stats.max_strength) << "the same rows in both passes";
      // Derivative planes: ix, iy, ixx, ixy, iyy.
      if (exact) {
        const int orders[5][2] = {{1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}};
        for (int i = 0; i < 5; ++i) {
          ASSERT_TRUE(
              GaussianFilter2d(img, sigma, orders[i][0], orders[i][1], tmp_plane, plane(i)).ok());
        }
      } else {
        ASSERT_TRUE(
            GaussianFilter2d(img, DifferenceSmoothingSigma(sigma), 0, 0, tmp_plane, plane(0)).ok());
      }
      const double s2 = double{sigma} * sigma;
      const double scale = s2 * s2 / (255.0 * 255.0 * 255.0 * kIdealCornerResponse);
      const ImageView<const float> resp{whole.data(), w, h, w};
      double max_resp = 0, max_err = 0;
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          double ix, iy, ixx, ixy, iyy;
          if (exact) {
            ix = plane(0).at(x, y), iy = plane(1).at(x, y), ixx = plane(2).at(x, y);
            ixy = plane(3).at(x, y), iyy = plane(4).at(x, y);
          } else {
            const ImageView<float> sm = plane(0);
            auto at = [&](int xx, int yy) {
              return double{sm.at(std::clamp(xx, 0, w - 1), std::clamp(yy, 0, h - 1))};
            };
            ix = 0.5 * (at(x + 1, y) - at(x - 1, y));
            iy = 0.5 * (at(x, y + 1) - at(x, y - 1));
            ixx = at(x + 1, y) - 2 * at(x, y) + at(x - 1, y);
            iyy = at(x, y + 1) - 2 * at(x, y) + at(x, y - 1);
            ixy =
                0.25 * (at(x + 1, y + 1) - at(x - 1, y + 1) - at(x + 1, y - 1) + at(x - 1, y - 1));
          }
          const double ref = std::fabs(iy * iy * ixx - 2 * ix * iy * ixy + ix * ix * iyy) * scale;
          max_resp = std::max(max_resp, ref);
          max_err = std::max(max_err, std::fabs(ref - resp.at(x, y)));
        }
      }
      EXPECT_GT(max_resp, 0.1) << sigma;
      EXPECT_LT(max_err, 1e-4 * max_resp) << (exact ? "exact" : "smoothed") << " sigma " << sigma;
    }
  }
}

// The corners taken from the response rows as they are computed (a ring of rows, the corners of
// a row once the rows within the NMS radius exist) are the local maxima of the whole response
// plane above the threshold: the same count and the same strengths, at every NMS radius up to
// the largest (the ring's depth) and near the image's top and bottom rows.
TEST(CornerBands, CornersOfTheRowRingAreTheMaximaOfTheWholePlane) {
  const int w = 1280, h = 800;
  std::vector<uint8_t> px;
  const ConstGrayView img = testing::NoisyTestScene(w, h, 2.0, 9, px);
  // Bright blocks with corners 3 rows from the top and from the bottom: the bottom ones are in the
  // rows taken after the last response row (the last `radius` rows) for radii from 3 up.
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if ((y >= h - 3 && x >= 300 && x < 340) || (y < 3 && x >= 700 && x < 740)) {
        px[static_cast<size_t>(y) * w + x] = 250;
      }
    }
  }
  auto scratch = MakeWorkspace<FilterScratch>(w, h);
  ASSERT_NE(scratch, nullptr);
  std::vector<float> whole(static_cast<size_t>(w) * h);
  for (const bool exact : {false, true}) {
    for (const int radius : {1, 3, kMaxCornerNmsRadiusPx}) {
      CornerConfig config;
      config.sigma_px = 2.0f;
      config.exact_derivatives = exact;
      config.reduce_large_scales = false;
      config.refine_to_vertex = false;
      config.nms_radius_px = radius;
      config.relative_threshold = 0.01f;
      Vector<Corner2D, kMaxCorners2d> corners;
      CornerStats stats;
      ASSERT_TRUE(DetectCorners(img, config, *scratch, corners, &stats).ok());
      float max_strength = 0.0f;
      ASSERT_TRUE(CornerResponse(img, config, *scratch, ImageView<float>{whole.data(), w, h, w},
                                 &max_strength)
                      .ok());
      const float threshold = std::max(config.threshold, config.relative_threshold * max_strength);
      std::vector<float> expected;
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const float v = whole[static_cast<size_t>(y) * w + x];
          if (!(v > threshold)) continue;
          bool is_max = true;
          for (int yy = std::max(0, y - radius); yy <= std::min(h - 1, y + radius); ++yy) {
            for (int xx = std::max(0, x - radius); xx <= std::min(w - 1, x + radius); ++xx) {
              const float q = whole[static_cast<size_t>(yy) * w + xx];
              const bool before = yy < y || (yy == y && xx < x);
              if (q > v || (before && q == v)) is_max = false;
            }
          }
          if (is_max) expected.push_back(v);
        }
      }
      std::sort(expected.begin(), expected.end(), std::greater<float>());
      size_t in_last_rows = 0;
      for (const Corner2D& c : corners) in_last_rows += c.y_px > h - 0.5f - radius;
      if (radius >= 3) {
        EXPECT_GT(in_last_rows, 0u) << "no corner in the last rows, r " << radius;
      }
      EXPECT_EQ(stats.threshold_used, threshold);
      EXPECT_EQ(stats.maxima_found, expected.size()) << exact << " r " << radius;
      ASSERT_GT(expected.size(), 10u);
      if (expected.size() > corners.size()) expected.resize(corners.size());
      ASSERT_EQ(corners.size(), expected.size()) << exact << " r " << radius;
      size_t differ = 0;
      for (size_t i = 0; i < corners.size(); ++i) differ += corners[i].strength != expected[i];
      EXPECT_EQ(differ, 0u) << exact << " r " << radius;
    }
  }
}

}  // namespace
}  // namespace sh
