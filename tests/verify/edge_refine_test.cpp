#include "recog/verify/edge_refine.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "tests/support/edge_scene.hpp"
#include "tests/support/test_models.hpp"

namespace sh {
namespace {

using testing::AxisAngleDeg;
using testing::RenderEdgeMap;

float RotationErrorDeg(const RigidTransform& a, const RigidTransform& b) {
  return RotationAngleDeg(a.R * b.R.transpose());
}

class EdgeRefineTest : public ::testing::Test, protected testing::CubeAndStarScene {};

// Edge maps rendered at the true pose (by ray casting, independent of the hidden-line code);
// a pose 1.5 deg and about 1.4 mm off is brought back close to the truth.
TEST_F(EdgeRefineTest, ConvergesToTheTruePoseFromNearby) {
  for (const PosedModel& truth : {cube_pose, star_pose}) {
    const testing::EdgeMapBuffer left = RenderEdgeMap(LeftView(calib), {truth});
    const testing::EdgeMapBuffer right = RenderEdgeMap(RightView(calib), {truth});
    RigidTransform pose = truth.cam_T_model;
    pose.R = AxisAngleDeg({0.3f, 1, -0.5f}, 1.5f) * pose.R;
    pose.t_mm += Eigen::Vector3f(0.8f, -0.6f, 1.0f);
    const float t0 = (pose.t_mm - truth.cam_T_model.t_mm).norm();
    const float r0 = RotationErrorDeg(pose, truth.cam_T_model);
    EdgeRefineResult result;
    ASSERT_TRUE(RefinePoseOnEdges(calib, left.const_view(), right.const_view(), *truth.model,
                                  nullptr, 0, EdgeRefineConfig{}, &pose, &result)
                    .ok());
    EXPECT_TRUE(result.refined) << truth.model->name;
    EXPECT_GE(result.inliers_after, result.inliers_before) << truth.model->name;
    EXPECT_LT(result.rms_px_after, result.rms_px_before) << truth.model->name;
    const float t1 = (pose.t_mm - truth.cam_T_model.t_mm).norm();
    const float r1 = RotationErrorDeg(pose, truth.cam_T_model);
    EXPECT_LT(t1, 0.35f * t0) << truth.model->name << ": " << t0 << " -> " << t1 << " mm";
    EXPECT_LT(r1, 0.35f * r0) << truth.model->name << ": " << r0 << " -> " << r1 << " deg";
  }
}

// Far from the truth the fit cannot find the edges: the pose is left as it was, never made worse
// by sliding onto other edges.
TEST_F(EdgeRefineTest, LeavesAFarPoseAlone) {
  const testing::EdgeMapBuffer left = RenderEdgeMap(LeftView(calib), {cube_pose, star_pose});
  const testing::EdgeMapBuffer right = RenderEdgeMap(RightView(calib), {cube_pose, star_pose});
  RigidTransform pose = cube_pose.cam_T_model;
  pose.R = AxisAngleDeg({0, 0, 1}, 20.0f) * pose.R;
  pose.t_mm += Eigen::Vector3f(6.0f, 0, 0);
  const RigidTransform start = pose;
  EdgeRefineResult result;
  ASSERT_TRUE(RefinePoseOnEdges(calib, left.const_view(), right.const_view(), cube, nullptr, 0,
                                EdgeRefineConfig{}, &pose, &result)
                  .ok());
  if (result.refined) {
    // Allowed only within the safeguard's reach.
    EXPECT_LE((pose.t_mm - start.t_mm).norm(), EdgeRefineConfig{}.max_shift_mm + 1e-3f);
    EXPECT_LE(RotationErrorDeg(pose, start), EdgeRefineConfig{}.max_turn_deg + 1e-3f);
  } else {
    EXPECT_EQ(pose.t_mm, start.t_mm);
    EXPECT_EQ(pose.R, start.R);
  }
}

TEST_F(EdgeRefineTest, RefusesMismatchedEdgeMaps) {
  testing::EdgeMapBuffer small(100, 80);
  RigidTransform pose = cube_pose.cam_T_model;
  EdgeRefineResult result;
  const Status s = RefinePoseOnEdges(calib, small.const_view(), small.const_view(), cube, nullptr,
                                     0, EdgeRefineConfig{}, &pose, &result);
  EXPECT_FALSE(s.ok());
  EXPECT_FALSE(result.refined);
}

}  // namespace
}  // namespace sh
