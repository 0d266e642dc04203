// Overlay drawing: the lines follow the visible samples and leave hidden edges out.
#include "recog/verify/draw_edges.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tests/support/edge_scene.hpp"
#include "tests/support/test_models.hpp"

namespace sh {
namespace {

using testing::AxisAngleDeg;

class DrawEdgesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(ComputeVisibleEdges(view, object, nullptr, 0, 1.0f, 1.0f, &visible).ok());
    for (int k = 0; k < visible.n_edges; ++k) {
      const VisibleEdge& ve = visible.edges[k];
      for (int i = 0; i < ve.n_samples; ++i) {
        Eigen::Vector2d p;
        ASSERT_TRUE(ProjectToPixel(
            calib.left,
            PointAtImageFraction(ve, SampleImageFraction(i, ve.n_samples)).cast<double>(), &p));
        samples.push_back(p);
      }
    }
  }
  double DistanceToSamples(double x, double y) const {
    double best = 1e9;
    for (const Eigen::Vector2d& p : samples)
      best = std::min(best, std::hypot(p.x() - x, p.y() - y));
    return best;
  }

  StereoCalibration calib = testing::TestCalibration();
  ViewCamera view = LeftView(calib);
  Model cube = testing::CubeModel();
  PosedModel object{&cube,
                    {AxisAngleDeg({1, 0.3f, 0}, 35) * AxisAngleDeg({0, 1, 0}, 40), {10, -5, 480}}};
  VisibleEdgeSet visible;
  std::vector<Eigen::Vector2d> samples;  // projected visible samples
  const int w = calib.left.width, h = calib.left.height;
};

TEST_F(DrawEdgesTest, GreyLinesCoverTheVisibleSamplesAndNothingElse) {
  std::vector<uint8_t> pixels(w * h, 7);
  const GrayView image{pixels.data(), w, h, w};
  ASSERT_TRUE(DrawVisibleEdges(view, visible, image, 200).ok());
  int drawn = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const uint8_t v = pixels[y * w + x];
      ASSERT_TRUE(v == 7 || v == 200);
      if (v == 200) {
        ++drawn;
        EXPECT_LT(DistanceToSamples(x, y), 1.5) << x << "," << y;
      }
    }
  }
  // Every sample has a drawn pixel next to it.
  for (const Eigen::Vector2d& p : samples) {
    bool near = false;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = static_cast<int>(std::lround(p.x())) + dx;
        const int y = static_cast<int>(std::lround(p.y())) + dy;
        near = near || pixels[y * w + x] == 200;
      }
    }
    EXPECT_TRUE(near) << p.transpose();
  }
  EXPECT_GE(drawn, static_cast<int>(samples.size()) * 8 / 10);
}

TEST_F(DrawEdgesTest, HiddenEdgesAreNotDrawn) {
  std::vector<uint8_t> pixels(w * h, 0);
  ASSERT_TRUE(DrawPosedModel(view, object, nullptr, 0, GrayView{pixels.data(), w, h, w}, 255).ok());
  const RigidTransform& T = object.cam_T_model;
  int hidden_checked = 0;
  for (int e = 0; e < cube.n_edges; ++e) {
    bool listed = false;
    for (int k = 0; k < visible.n_edges; ++k) listed = listed || visible.edges[k].edge == e;
    if (listed) continue;
    // Points of the hidden edge away from the visible outline stay blank.
    const Eigen::Vector3f a = T * cube.corner(cube.edges[e].a),
                          b = T * cube.corner(cube.edges[e].b);
    for (float t = 0.05f; t < 1.0f; t += 0.05f) {
      Eigen::Vector2d p;
      ASSERT_TRUE(ProjectToPixel(calib.left, (a + t * (b - a)).cast<double>(), &p));
      if (DistanceToSamples(p.x(), p.y()) < 3.0) continue;
      ++hidden_checked;
      EXPECT_EQ(pixels[std::lround(p.y()) * w + std::lround(p.x())], 0);
    }
  }
  EXPECT_GT(hidden_checked, 20);
}

TEST_F(DrawEdgesTest, RgbDrawsTheSamePixelsInColour) {
  std::vector<uint8_t> grey(w * h, 0);
  std::vector<Rgb8> rgb(w * h, Rgb8{1, 2, 3});
  ASSERT_TRUE(DrawVisibleEdges(view, visible, GrayView{grey.data(), w, h, w}, 255).ok());
  ASSERT_TRUE(
      DrawVisibleEdges(view, visible, ImageView<Rgb8>{rgb.data(), w, h, w}, Rgb8{255, 40, 0}).ok());
  for (int i = 0; i < w * h; ++i) {
    const Rgb8 c = rgb[i];
    if (grey[i] == 255) {
      EXPECT_TRUE(c.r == 255 && c.g == 40 && c.b == 0);
    } else {
      EXPECT_TRUE(c.r == 1 && c.g == 2 && c.b == 3);
    }
  }
}

TEST_F(DrawEdgesTest, ObjectPartlyOutsideIsClipped) {
  // Padding around the image must stay untouched: the view's stride leaves a margin.
  const int stride = w + 16;
  std::vector<uint8_t> pixels(stride * (h + 1), 0);
  const PosedModel half_out{&cube, {object.cam_T_model.R, {240, 150, 480}}};
  ASSERT_TRUE(
      DrawPosedModel(view, half_out, nullptr, 0, GrayView{pixels.data(), w, h, stride}, 9).ok());
  int inside = 0;
  for (int y = 0; y <= h; ++y) {
    for (int x = 0; x < stride; ++x) {
      if (pixels[y * stride + x] == 0) continue;
      EXPECT_TRUE(x < w && y < h) << x << "," << y;
      ++inside;
    }
  }
  EXPECT_GT(inside, 20);
}

TEST_F(DrawEdgesTest, WrongImageSizeIsAnError) {
  std::vector<uint8_t> pixels(100 * 100, 0);
  EXPECT_EQ(DrawVisibleEdges(view, visible, GrayView{pixels.data(), 100, 100, 100}, 1).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(DrawVisibleEdges(view, visible, GrayView{}, 1).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace sh
