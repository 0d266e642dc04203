// The faint-edge test of the verifier (VerifyConfig::faint_edges): model edges confirmed by a
// consistent grey-level step along them where the edge map has no pixels. The grey images are
// ray cast (tests/support/edge_scene.hpp) with chosen face brightnesses and added noise; the
// edge maps are left empty, so every confirmation comes from the grey images.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "recog/verify/verify.hpp"
#include "tests/support/edge_scene.hpp"

namespace sh {
namespace {

using testing::EdgeMapBuffer;
using testing::RenderRegions;

struct GreyBuffer {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;
  ConstGrayView view() const { return {pixels.data(), width, height, width}; }
};

// Grey level of a pixel from its region (RenderRegions) and position.
using Shading = std::function<float(int region, int x, int y)>;

GreyBuffer Shade(const CameraIntrinsics& cam, const std::vector<int>& regions,
                 const Shading& shading, float noise_sigma, uint32_t seed) {
  GreyBuffer out{cam.width, cam.height, std::vector<uint8_t>(regions.size())};
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, noise_sigma > 0 ? noise_sigma : 1.0f);
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const size_t i = static_cast<size_t>(y) * cam.width + x;
      float g = shading(regions[i], x, y);
      if (noise_sigma > 0) g += noise(rng);
      out.pixels[i] = static_cast<uint8_t>(std::lround(std::fmin(255.0f, std::fmax(0.0f, g))));
    }
  }
  return out;
}

// Background 140; the cube's faces 146, 152, ... (6 grey levels apart, and from the background),
// as a light part on a light table under diffuse light.
float FaintFaces(int region, int, int) { return region == 0 ? 140.0f : 140.0f + 6.0f * region; }

// The cube `step` levels above a background of 140, all its faces alike: only its outline steps.
Shading Silhouette(float step) {
  return [step](int region, int, int) { return region == 0 ? 140.0f : 140.0f + step; };
}

class FaintEdgeTest : public ::testing::Test, protected testing::CubeAndStarScene {
 protected:
  static constexpr float kNoiseSigma = 2.0f;

  void SetUp() override {
    // The cube's region maps are the same for every case: drawn once for the suite.
    static const std::vector<int> kRegions[2] = {RenderRegions(LeftView(calib), {cube_pose}),
                                                 RenderRegions(RightView(calib), {cube_pose})};
    regions_ = kRegions;
    config_.faint_edges = true;
    config_.min_fraction = 0.55f;
  }

  // Grey images of the cube shaded by `shading` with noise of `noise_sigma`, told to the verifier
  // as `told_sigma`.
  VerifyResult Verify(const PosedModel& hypothesis, const Shading& shading, float noise_sigma,
                      float told_sigma, const VerifyConfig& config) const {
    const GreyBuffer left = Shade(calib.left, regions_[0], shading, noise_sigma, 1);
    const GreyBuffer right = Shade(calib.right, regions_[1], shading, noise_sigma, 2);
    const Result<VerifyResult> r =
        VerifyHypothesis(calib, empty_left_.const_view(), empty_right_.const_view(), hypothesis,
                         nullptr, 0, config, {left.view(), told_sigma}, {right.view(), told_sigma});
    EXPECT_TRUE(r.ok()) << r.status().message();
    return r.ok() ? *r : VerifyResult{};
  }
  VerifyResult Verify(const PosedModel& hypothesis, const Shading& shading) const {
    return Verify(hypothesis, shading, kNoiseSigma, kNoiseSigma, config_);
  }

  const std::vector<int>* regions_ = nullptr;
  VerifyConfig config_;
  EdgeMapBuffer empty_left_{calib.left.width, calib.left.height};
  EdgeMapBuffer empty_right_{calib.right.width, calib.right.height};
};

TEST_F(FaintEdgeTest, StepsOfAFewGreyLevelsConfirmTheTruePose) {
  const VerifyResult r = Verify(cube_pose, FaintFaces);
  EXPECT_TRUE(r.accepted) << VerifyReasonName(r.reason) << " " << r.score_left << " "
                          << r.score_right;
  // A cube in general position shows 9 edges; the shortest may fall under the minimum length.
  EXPECT_GE(r.faint_edges_left, 7);
  EXPECT_GE(r.faint_edges_right, 7);
  EXPECT_GT(r.score_left, 0.8f);
  EXPECT_GT(r.score_right, 0.8f);
}

TEST_F(FaintEdgeTest, WithoutTheTestTheSameImagesConfirmNothing) {
  VerifyConfig off = config_;
  off.faint_edges = false;
  const VerifyResult r = Verify(cube_pose, FaintFaces, kNoiseSigma, kNoiseSigma, off);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.confirmed_left + r.confirmed_right, 0);
  EXPECT_EQ(r.faint_edges_left + r.faint_edges_right, 0);
}

TEST_F(FaintEdgeTest, NoiseAloneConfirmsNothing) {
  const VerifyResult r = Verify(cube_pose, [](int, int, int) { return 140.0f; });
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.faint_edges_left + r.faint_edges_right, 0);
}

TEST_F(FaintEdgeTest, ShadingRampConfirmsNothing) {
  // 1.5 grey levels per pixel in x and 1 in y: across an edge, 4 px apart, up to 7 levels, but
  // the same again beyond either side of it. Then a steeper one.
  const Eigen::Vector2d c(calib.left.cx, calib.left.cy);
  for (const Eigen::Vector2d& slope : {Eigen::Vector2d(1.5, 1.0), Eigen::Vector2d(-2.5, 2.0)}) {
    const VerifyResult r = Verify(cube_pose, [&](int, int x, int y) {
      return static_cast<float>(128.0 + slope.x() * (x - c.x()) + slope.y() * (y - c.y()));
    });
    EXPECT_EQ(r.faint_edges_left + r.faint_edges_right, 0) << slope.transpose();
  }
}

TEST_F(FaintEdgeTest, StrongEdgeAcrossTheModelConfirmsNothing) {
  // One straight step of 60 levels through the cube's middle, nearly along the image's
  // diagonal: a model edge it crosses steps in one place only.
  const Eigen::Vector2d centre(calib.left.cx, calib.left.cy);
  const VerifyResult r = Verify(cube_pose, [&](int, int x, int y) {
    return (x - centre.x()) + 0.9 * (y - centre.y()) > 0 ? 180.0f : 120.0f;
  });
  EXPECT_FALSE(r.accepted);
  EXPECT_LT(r.score_left, 0.2f);
  EXPECT_LT(r.score_right, 0.2f);
}

TEST_F(FaintEdgeTest, StepAlongPartOfAnEdgeDoesNotConfirmIt) {
  // The cube's outline 60 levels deep, but only in a band of 24 columns through its middle: the
  // edges crossing the band step strongly along a part of their length (as where a wrong model
  // shares part of an edge with a true object) and not at all elsewhere.
  const int x_mid = static_cast<int>(calib.left.cx);
  const auto band = [&](int region, int x, int) {
    return region != 0 && std::abs(x - x_mid) < 12 ? 200.0f : 140.0f;
  };
  const VerifyResult r = Verify(cube_pose, band);
  EXPECT_FALSE(r.accepted) << r.score_left << " " << r.score_right;
  EXPECT_LE(r.faint_edges_left + r.faint_edges_right, 2);
}

TEST_F(FaintEdgeTest, PoseShiftedSidewaysIsRejected) {
  for (const Eigen::Vector3f& shift : {Eigen::Vector3f(10, 0, 0), Eigen::Vector3f(0, -10, 0)}) {
    PosedModel moved = cube_pose;
    moved.cam_T_model.t_mm += shift;
    const VerifyResult r = Verify(moved, FaintFaces);
    EXPECT_FALSE(r.accepted) << shift.transpose() << ": " << r.score_left << " " << r.score_right;
  }
}

TEST_F(FaintEdgeTest, StepMustReachTheFloorOnNoiseFreeImages) {
  // Without noise (a rendered image), faint_min_step alone decides: an outline 2 levels above
  // the background is below the default 3, one of 4 levels is above it.
  const VerifyResult low = Verify(cube_pose, Silhouette(2.0f), 0.0f, 0.0f, config_);
  EXPECT_EQ(low.faint_edges_left + low.faint_edges_right, 0);
  const VerifyResult high = Verify(cube_pose, Silhouette(4.0f), 0.0f, 0.0f, config_);
  EXPECT_GE(high.faint_edges_left, 5);  // the outline of a cube in general position has 6
  EXPECT_GE(high.faint_edges_right, 5);
}

TEST_F(FaintEdgeTest, StepMustStandOutOfTheToldNoise) {
  // An outline 6 levels deep is found with the noise told right, not when told it is 10 levels
  // (under the 1.5-sigma step).
  const VerifyResult right = Verify(cube_pose, Silhouette(6.0f), kNoiseSigma, kNoiseSigma, config_);
  EXPECT_GE(right.faint_edges_left + right.faint_edges_right, 10);
  const VerifyResult r = Verify(cube_pose, Silhouette(6.0f), kNoiseSigma, 10.0f, config_);
  EXPECT_EQ(r.faint_edges_left + r.faint_edges_right, 0);
}

TEST_F(FaintEdgeTest, BadGreyImageOrSettingsAreErrors) {
  const GreyBuffer small{320, 240, std::vector<uint8_t>(size_t{320} * 240, 128)};
  EXPECT_EQ(VerifyHypothesis(calib, empty_left_.const_view(), empty_right_.const_view(), cube_pose,
                             nullptr, 0, config_, {small.view(), 1.0f}, {})
                .status()
                .code(),
            StatusCode::kInvalidArgument);
  for (auto mutate :
       {+[](VerifyConfig& c) { c.faint_offset_px = 0; },
        +[](VerifyConfig& c) { c.faint_min_step = 0; }, +[](VerifyConfig& c) { c.faint_snr = -1; },
        +[](VerifyConfig& c) { c.faint_min_step_sigmas = NAN; },
        +[](VerifyConfig& c) { c.faint_min_samples = 2; }}) {
    VerifyConfig bad = config_;
    mutate(bad);
    EXPECT_EQ(CheckVerifyConfig(bad).code(), StatusCode::kInvalidArgument);
  }
}

}  // namespace
}  // namespace sh
