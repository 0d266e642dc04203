// Pose from one image: the first pose of a hypothesis, the fit to matched features through the
// lens distortion, resting starts.
#include "recog/mono/mono_pose.hpp"

#include <gtest/gtest.h>

#include "tests/mono/mono_fixtures.hpp"

namespace sh {
namespace {

using testing::BuildTable;
using testing::PoseFromAxisAngle;
using testing::ProjectModel;
using testing::ReferenceModel;
using testing::ThesisCamera;

using testing::RotationErrorDeg;
using testing::ThesisTable;

TEST(PoseFromHypothesis, BestHypothesisOfTheBasesIsNearTheTruth) {
  const Model& cube = ReferenceModel("cube");
  const testing::ModelVoter v = testing::VoterOf(cube);
  auto& table = v.table;
  auto& voter = v.voter;
  const CameraIntrinsics cam = ThesisCamera();
  const RigidTransform truth =
      PoseFromAxisAngle({0.3f, 1.0f, 0.2f}, 50.0f, {30.0f, -20.0f, 450.0f});
  const testing::ProjectedFeatures f = ProjectModel(cam, cube, truth);
  ASSERT_GE(f.ideal_points.size(), 6u);
  float best_t = 1e9f, best_r = 180.0f;
  const int n = static_cast<int>(f.ideal_points.size());
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (i == j) continue;
      AspectHypothesis h[4];
      const int k = testing::VotePair(*voter, f.ideal_points, f.ideal_lines, i, j, 0.3f, h, 4);
      const Frame2d frame = SimilarityFrame(f.ideal_points[i].xy, f.ideal_points[j].xy);
      for (int q = 0; q < k; ++q) {
        const AspectBasis& b = table->view.basis(h[q].basis);
        const RigidTransform pose =
            PoseFromHypothesis(table->view.aspect(b.aspect), b, frame, static_cast<float>(cam.fx));
        const float dt = (pose.t_mm - truth.t_mm).norm();
        const float dr = RotationErrorDeg(cube, truth.R, pose.R);
        if (dt + dr < best_t + best_r) best_t = dt, best_r = dr;
      }
    }
  }
  // Weak perspective and a 10-degree aspect grid: within a few centimetres and degrees.
  EXPECT_LT(best_t, 20.0f);
  EXPECT_LT(best_r, 8.0f);
}

// Exact features of a posed model, matched at a disturbed pose and fitted back.
struct FitCase {
  CameraIntrinsics cam;
  const Model* model = nullptr;
  RigidTransform truth;
};

PoseMatches MatchAt(const FitCase& c, const RigidTransform& pose, float gate) {
  const testing::ProjectedFeatures f = ProjectModel(c.cam, *c.model, c.truth);
  VisibleEdgeSet visible;
  EXPECT_TRUE(ComputeVisibleEdges({c.cam, RigidTransform::Identity()}, {c.model, pose}, nullptr, 0,
                                  2.0f, 1.0f, &visible)
                  .ok());
  PoseScene scene;
  scene.corners = f.corners.data();
  scene.n_corners = static_cast<int>(f.corners.size());
  scene.lines = f.lines.data();
  scene.n_lines = static_cast<int>(f.lines.size());
  MatchConfig mc;
  mc.corner_gate_px = mc.line_gate_px = gate;
  PoseMatches m;
  MatchFeatures(c.cam, *c.model, pose, visible, scene, mc, &m);
  return m;
}

TEST(FitPose, ConvergesThroughTheLensDistortion) {
  CameraIntrinsics cam = ThesisCamera();
  cam.k1 = -0.21;  // the wide camera's barrel distortion, used directly
  cam.k2 = 0.09;
  cam.p1 = 0.001;
  const FitCase c{cam, &ReferenceModel("hexagon"),
                  PoseFromAxisAngle({1.0f, 0.4f, -0.3f}, 65.0f, {-40.0f, 25.0f, 420.0f})};
  RigidTransform pose = c.truth;
  pose.R = Eigen::AngleAxisf(0.04f, Eigen::Vector3f(0.2f, 1, 0.5f).normalized()) * pose.R;
  pose.t_mm += Eigen::Vector3f(2.0f, -1.5f, 6.0f);
  auto scratch = std::make_unique<FitScratch>();
  for (float gate : {12.0f, 5.0f, 3.0f}) {
    const PoseMatches m = MatchAt(c, pose, gate);
    ASSERT_GE(m.n_points + m.n_lines, 6);
    const FitResult r = FitPose(cam, m, FitConfig{}, scratch.get(), &pose);
    EXPECT_GT(r.iterations, 0);
  }
  EXPECT_LT((pose.t_mm - c.truth.t_mm).norm(), 0.5f);
  EXPECT_LT(RotationAngleDeg(pose.R.transpose() * c.truth.R), 0.2f);
  const PoseMatches final_matches = MatchAt(c, pose, 3.0f);
  EXPECT_EQ(final_matches.n_points, final_matches.corners_expected);
  EXPECT_GE(final_matches.n_lines, final_matches.pieces_expected - 1);
}

TEST(FitRestingPose, FindsHeadingAndPositionOnTheTable) {
  const TablePlane table = ThesisTable();
  const Model& wedge = ReferenceModel("wedge");
  StableFaces faces;
  ASSERT_TRUE(ComputeStableFaces(wedge, 0.5f, &faces).ok());
  auto scratch = std::make_unique<FitScratch>();
  for (int f = 0; f < faces.count; ++f) {
    const RestingPose truth{f, 1.1f, 30.0f, -10.0f};
    const FitCase c{ThesisCamera(), &wedge, RestingTransform(table, faces, truth)};
    RestingPose pose{f, 1.1f + 0.08f, 33.0f, -12.0f};
    for (float gate : {12.0f, 5.0f, 3.0f}) {
      const PoseMatches m = MatchAt(c, RestingTransform(table, faces, pose), gate);
      ASSERT_GE(m.n_points + m.n_lines, 4) << "face " << f;
      FitRestingPose(c.cam, m, table, faces, FitConfig{}, scratch.get(), &pose);
    }
    EXPECT_EQ(pose.face, f);
    EXPECT_NEAR(pose.x_mm, truth.x_mm, 0.1f) << "face " << f;
    EXPECT_NEAR(pose.y_mm, truth.y_mm, 0.1f) << "face " << f;
    EXPECT_NEAR(pose.heading_rad, truth.heading_rad, 0.002f) << "face " << f;
  }
}

TEST(MatchFeatures, PairsEachVisibleCornerWithItsImageCorner) {
  const FitCase c{ThesisCamera(), &ReferenceModel("cube"),
                  PoseFromAxisAngle({0.5f, 1.0f, 0.0f}, 40.0f, {0.0f, 0.0f, 400.0f})};
  const PoseMatches m = MatchAt(c, c.truth, 2.0f);
  EXPECT_EQ(m.n_points, 7);
  EXPECT_EQ(m.corners_expected, 7);
  for (int i = 0; i < m.n_points; ++i) {
    Eigen::Vector2d px;
    ASSERT_TRUE(ProjectToPixel(c.cam, (c.truth * m.points[i].model).cast<double>(), &px));
    EXPECT_LT((px.cast<float>() - m.points[i].px).norm(), 1e-3f);
  }
  // Far from any feature: nothing matches.
  RigidTransform away = c.truth;
  away.t_mm.x() += 200.0f;
  const PoseMatches none = MatchAt(c, away, 3.0f);
  EXPECT_EQ(none.n_points + none.n_lines, 0);
}

}  // namespace
}  // namespace sh
