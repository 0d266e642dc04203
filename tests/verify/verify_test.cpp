// Verification against edge maps rendered from the true scene.
#include "recog/verify/verify.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "tests/support/edge_scene.hpp"
#include "tests/support/test_models.hpp"

namespace sh {
namespace {

using testing::AxisAngleDeg;
using testing::EdgeMapBuffer;
using testing::RenderEdgeMap;

class VerifyTest : public ::testing::Test, protected testing::CubeAndStarScene {
 protected:
  struct Maps {
    EdgeMapBuffer left, right;
  };
  Maps Render(const std::vector<PosedModel>& scene) const {
    return {RenderEdgeMap(LeftView(calib), scene), RenderEdgeMap(RightView(calib), scene)};
  }
  VerifyResult Verify(const Maps& maps, const PosedModel& hypothesis,
                      const std::vector<PosedModel>& accepted = {},
                      const VerifyConfig& config = VerifyConfig{}) const {
    Result<VerifyResult> r =
        VerifyHypothesis(calib, maps.left.const_view(), maps.right.const_view(), hypothesis,
                         accepted.data(), accepted.size(), config);
    EXPECT_TRUE(r.ok()) << r.status().message();
    return r.ok() ? *r : VerifyResult{};
  }
};

TEST_F(VerifyTest, TruePoseIsAcceptedWithScoresNearOne) {
  for (const PosedModel& truth : {cube_pose, star_pose}) {
    const Maps maps = Render({truth});
    const VerifyResult r = Verify(maps, truth);
    EXPECT_TRUE(r.accepted) << truth.model->name << ": " << VerifyReasonName(r.reason);
    EXPECT_EQ(r.reason, VerifyReason::kAccepted);
    // Samples within a pixel or two of a corner can miss: there the edge detector's gradient
    // direction bends towards the other edge.
    EXPECT_GT(r.score_left, 0.85f) << truth.model->name;
    EXPECT_GT(r.score_right, 0.85f) << truth.model->name;
    EXPECT_GT(r.samples_left, 100);
    EXPECT_GT(r.samples_right, 100);
    EXPECT_LE(r.confirmed_left, r.samples_left);
  }
}

TEST_F(VerifyTest, PoseShiftedTenMillimetresSidewaysIsRejected) {
  // 10 mm across the view is about 16 px, four times the search reach. (Along the view, 10 mm
  // changes the left image by a 2 % scale and the right one by about 3 px: within reach.)
  for (const PosedModel& truth : {cube_pose, star_pose}) {
    const Maps maps = Render({truth});
    const Eigen::Vector3f shifts[] = {{10, 0, 0}, {0, 10, 0}, {-7.07f, 7.07f, 0}};
    for (const Eigen::Vector3f& shift : shifts) {
      PosedModel moved = truth;
      moved.cam_T_model.t_mm += shift;
      const VerifyResult r = Verify(maps, moved);
      EXPECT_FALSE(r.accepted) << truth.model->name << " shifted by " << shift.transpose()
                               << ": scores " << r.score_left << " " << r.score_right;
      EXPECT_LT(std::min(r.score_left, r.score_right), VerifyConfig{}.min_fraction);
    }
  }
}

TEST_F(VerifyTest, PoseRotatedFifteenDegreesInTheImagePlaneIsRejected) {
  for (const PosedModel& truth : {cube_pose, star_pose}) {
    const Maps maps = Render({truth});
    for (const float angle_deg : {-15.0f, 15.0f}) {
      PosedModel turned = truth;  // about the viewing axis through the object's centre
      turned.cam_T_model.R = AxisAngleDeg({0, 0, 1}, angle_deg) * truth.cam_T_model.R;
      const VerifyResult r = Verify(maps, turned);
      EXPECT_FALSE(r.accepted) << truth.model->name << " turned by " << angle_deg << ": scores "
                               << r.score_left << " " << r.score_right;
    }
  }
}

TEST_F(VerifyTest, PoseRotatedFifteenDegreesScoresFarBelowTheTruth) {
  // Turned out of the image plane about an axis through its centre, an object keeps the edges
  // near that axis in place, so part of the samples still confirm; the score drops well below
  // the true pose's in at least one image, and a strict fraction rejects every such pose.
  VerifyConfig strict;
  strict.min_fraction = 0.75f;
  for (const PosedModel& truth : {cube_pose, star_pose}) {
    const Maps maps = Render({truth});
    const VerifyResult true_result = Verify(maps, truth, {}, strict);
    EXPECT_TRUE(true_result.accepted) << truth.model->name;
    const float true_score = std::min(true_result.score_left, true_result.score_right);
    const Eigen::Vector3f axes[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (const Eigen::Vector3f& axis : axes) {
      for (const float angle_deg : {-15.0f, 15.0f}) {
        for (const bool model_axis : {true, false}) {
          PosedModel turned = truth;
          turned.cam_T_model.R = model_axis ? truth.cam_T_model.R * AxisAngleDeg(axis, angle_deg)
                                            : AxisAngleDeg(axis, angle_deg) * truth.cam_T_model.R;
          const VerifyResult r = Verify(maps, turned, {}, strict);
          EXPECT_FALSE(r.accepted)
              << truth.model->name << " turned about " << (model_axis ? "model " : "camera ")
              << axis.transpose() << " by " << angle_deg << ": scores " << r.score_left << " "
              << r.score_right;
          EXPECT_LT(std::min(r.score_left, r.score_right), true_score - 0.2f);
        }
      }
    }
  }
}

TEST_F(VerifyTest, EdgePixelsWithWrongOrientationDoNotConfirm) {
  Maps maps = Render({cube_pose});
  for (EdgeMapBuffer* map : {&maps.left, &maps.right}) {
    for (uint8_t& o : map->orientation) o = static_cast<uint8_t>(o + 128);  // turned 90 degrees
  }
  const VerifyResult r = Verify(maps, cube_pose);
  EXPECT_FALSE(r.accepted);
  EXPECT_LT(r.score_left, 0.1f);
  EXPECT_LT(r.score_right, 0.1f);
  EXPECT_GT(r.samples_left, 100);  // the samples were there, just not confirmed
}

TEST_F(VerifyTest, AngleToleranceIsRespected) {
  Maps maps = Render({cube_pose});
  // Orientation turned by 20 degrees: outside the default 10, inside a 30-degree tolerance.
  const uint8_t turn = static_cast<uint8_t>(20.0 * 256.0 / 180.0 + 0.5);
  for (EdgeMapBuffer* map : {&maps.left, &maps.right}) {
    for (uint8_t& o : map->orientation) o = static_cast<uint8_t>(o + turn);
  }
  EXPECT_FALSE(Verify(maps, cube_pose).accepted);
  VerifyConfig loose;
  loose.max_angle_deg = 30.0f;
  EXPECT_TRUE(Verify(maps, cube_pose, {}, loose).accepted);
}

TEST_F(VerifyTest, EmptyEdgeMapRejects) {
  const EdgeMapBuffer left(calib.left.width, calib.left.height);
  const EdgeMapBuffer right(calib.right.width, calib.right.height);
  const VerifyResult r = Verify({left, right}, star_pose);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, VerifyReason::kLowScoreLeft);
  EXPECT_EQ(r.score_left, 0.0f);
  EXPECT_EQ(r.confirmed_right, 0);
}

TEST_F(VerifyTest, PoseBehindCameraIsRejectedWithReason) {
  const Maps maps = Render({cube_pose});
  PosedModel behind = cube_pose;
  behind.cam_T_model.t_mm = {0, 0, -480};
  VerifyResult r = Verify(maps, behind);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, VerifyReason::kBehindCamera);
  behind.cam_T_model.t_mm = {0, 0, 5};  // through the camera plane
  r = Verify(maps, behind);
  EXPECT_EQ(r.reason, VerifyReason::kBehindCamera);
}

TEST_F(VerifyTest, ObjectOutsideTheImageHasTooFewSamples) {
  const Maps maps = Render({cube_pose});
  PosedModel outside = cube_pose;
  outside.cam_T_model.t_mm = {600, 0, 480};
  const VerifyResult r = Verify(maps, outside);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, VerifyReason::kTooFewSamplesLeft);
  EXPECT_LT(r.samples_left, VerifyConfig{}.min_samples);
}

TEST_F(VerifyTest, SamplesOutsideTheImageAreIgnored) {
  // Half the cube beyond the left image's right border (x = 756 px): the in-image part decides.
  PosedModel edge_of_view = cube_pose;
  edge_of_view.cam_T_model.t_mm = {225, 0, 480};
  const Maps maps = Render({edge_of_view});
  const VerifyResult r = Verify(maps, edge_of_view);
  const VerifyResult centred = Verify(Render({cube_pose}), cube_pose);
  EXPECT_LT(r.samples_left, centred.samples_left);
  EXPECT_GT(r.score_left, 0.9f);
}

TEST_F(VerifyTest, OccludedPartsOfAnObjectBehindAnAcceptedOneAreNotSampled) {
  const PosedModel front{&cube, {AxisAngleDeg({0, 1, 0}, 20), {0, 0, 430}}};
  const PosedModel back{&star, {AxisAngleDeg({1, 0, 0}, 150), {25, 10, 540}}};
  const Maps maps = Render({front, back});
  const VerifyResult with_front = Verify(maps, back, {front});
  const VerifyResult ignoring_front = Verify(maps, back);
  EXPECT_TRUE(with_front.accepted) << VerifyReasonName(with_front.reason);
  EXPECT_GT(with_front.score_left, 0.9f);
  EXPECT_LT(with_front.samples_left, ignoring_front.samples_left);
  EXPECT_LT(ignoring_front.score_left, with_front.score_left);
  // The accepted object itself still verifies.
  EXPECT_TRUE(Verify(maps, front).accepted);
}

TEST_F(VerifyTest, ObjectCompletelyBehindAnAcceptedOneIsRejected) {
  const PosedModel front{&cube, {AxisAngleDeg({0, 1, 0}, 10), {0, 0, 400}}};
  const PosedModel hidden{&cube, {AxisAngleDeg({0, 1, 0}, 10), {0, 0, 650}}};
  const Maps maps = Render({front, hidden});
  const VerifyResult r = Verify(maps, hidden, {front});
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, VerifyReason::kTooFewSamplesLeft);
  EXPECT_EQ(r.samples_left, 0);
}

TEST_F(VerifyTest, BadInputIsAnErrorNotARejection) {
  const Maps maps = Render({cube_pose});
  const VerifyConfig config;
  const EdgeMapBuffer small(320, 240);
  EXPECT_EQ(VerifyHypothesis(calib, small.const_view(), maps.right.const_view(), cube_pose, nullptr,
                             0, config)
                .status()
                .code(),
            StatusCode::kInvalidArgument);
  EXPECT_FALSE(VerifyHypothesis(calib, ConstEdgeMapView{}, maps.right.const_view(), cube_pose,
                                nullptr, 0, config)
                   .ok());
  EXPECT_FALSE(VerifyHypothesis(calib, maps.left.const_view(), maps.right.const_view(),
                                PosedModel{}, nullptr, 0, config)
                   .ok());
  for (auto mutate : {+[](VerifyConfig& c) { c.max_distance_px = -1; },
                      +[](VerifyConfig& c) { c.max_angle_deg = 120; },
                      +[](VerifyConfig& c) { c.min_fraction = 1.5f; },
                      +[](VerifyConfig& c) { c.sample_step_px = 0; },
                      +[](VerifyConfig& c) { c.min_samples = 0; }}) {
    VerifyConfig bad;
    mutate(bad);
    EXPECT_EQ(VerifyHypothesis(calib, maps.left.const_view(), maps.right.const_view(), cube_pose,
                               nullptr, 0, bad)
                  .status()
                  .code(),
              StatusCode::kInvalidArgument);
  }
}

TEST_F(VerifyTest, DistanceToleranceIsRespected) {
  const Maps maps = Render({cube_pose});
  // 3 mm at 480 mm is about 5 px: out of reach at 2 px, within reach at 8 px.
  PosedModel moved = cube_pose;
  moved.cam_T_model.t_mm += Eigen::Vector3f(2.1f, 2.1f, 0);
  VerifyConfig tight;
  tight.max_distance_px = 2.0f;
  VerifyConfig wide;
  wide.max_distance_px = 8.0f;
  EXPECT_FALSE(Verify(maps, moved, {}, tight).accepted);
  EXPECT_TRUE(Verify(maps, moved, {}, wide).accepted);
}

}  // namespace
}  // namespace sh
