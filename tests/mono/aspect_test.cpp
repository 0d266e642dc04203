// Aspect models: what a view of a model shows, with true hidden lines.
#include "recog/mono/aspect.hpp"

#include <gtest/gtest.h>

#include "recog/mono/view_sphere.hpp"
#include "tests/mono/mono_fixtures.hpp"

namespace sh {
namespace {

using testing::ReferenceModel;

TEST(Aspect, CubeFromAGeneralViewShowsSevenCornersAndNineEdges) {
  const Model& cube = ReferenceModel("cube");
  AspectView a;
  ASSERT_TRUE(ComputeAspect(cube, ViewVector(55.0f, 30.0f), AspectConfig{}, &a).ok());
  EXPECT_EQ(a.n_corners, 7);
  EXPECT_EQ(a.n_segments, 9);
  EXPECT_EQ(a.dropped_segments, 0);
  // The virtual camera looks at the centroid from the view direction, at 10 mean radii.
  const Eigen::Vector3f centre = a.cam_T_model * ModelCentroid(cube);
  EXPECT_NEAR(centre.x(), 0.0f, 1e-3f);
  EXPECT_NEAR(centre.y(), 0.0f, 1e-3f);
  EXPECT_NEAR(centre.z(), 10.0f * MeanCornerRadiusMm(cube), 1e-2f);
  // Corners and segments are projections of the model's corners and edges.
  for (int i = 0; i < a.n_corners; ++i) {
    const Eigen::Vector3f p = a.cam_T_model * cube.corner(a.corners[i].corner);
    EXPECT_LT((a.corners[i].xy - Eigen::Vector2f(p.x() / p.z(), p.y() / p.z())).norm(), 1e-6f);
  }
}

TEST(Aspect, TopViewShowsOnlyTheTopFace) {
  const Model& cube = ReferenceModel("cube");
  AspectView a;
  ASSERT_TRUE(ComputeAspect(cube, Eigen::Vector3f(0, 0, 1), AspectConfig{}, &a).ok());
  EXPECT_EQ(a.n_corners, 4);
  EXPECT_EQ(a.n_segments, 4);
  for (int i = 0; i < a.n_corners; ++i) EXPECT_GT(cube.corner(a.corners[i].corner).z(), 0.0f);
}

TEST(Aspect, StarHidesPartsOfItsOwnEdgesInSomeViews) {
  // The star is not convex: from low views its points hide pieces of the edges behind them,
  // which the aspect keeps as shorter segments (a back-face test would keep them whole).
  const Model& star = ReferenceModel("star");
  int partial_views = 0;
  AspectView a;
  for (float theta = 60.0f; theta <= 90.0f; theta += 10.0f) {
    for (float phi = 0.0f; phi < 72.0f; phi += 6.0f) {
      ASSERT_TRUE(ComputeAspect(star, ViewVector(theta, phi), AspectConfig{}, &a).ok());
      Eigen::Vector2f projected[kMaxModelCorners];
      for (int i = 0; i < star.n_corners; ++i) {
        const Eigen::Vector3f p = a.cam_T_model * star.corner(i);
        projected[i] = {p.x() / p.z(), p.y() / p.z()};
      }
      bool partial = false;
      for (int s = 0; s < a.n_segments; ++s) {
        const ModelEdge& e = star.edges[a.segments[s].edge];
        const float whole = (projected[e.b] - projected[e.a]).norm();
        partial = partial || (a.segments[s].b - a.segments[s].a).norm() < 0.95f * whole;
      }
      partial_views += partial;
    }
  }
  EXPECT_GT(partial_views, 0);
}

TEST(Aspect, CornersNeedTwoEdgesAtAProperAngle) {
  // Seen exactly along a cube's side face, that face's edges project onto one line: its
  // corners are not 2-D corners.
  const Model& cube = ReferenceModel("cube");
  AspectView a;
  ASSERT_TRUE(ComputeAspect(cube, Eigen::Vector3f(1, 0, 0), AspectConfig{}, &a).ok());
  EXPECT_EQ(a.n_corners, 4);  // the rectangle of the face seen head-on
  AspectConfig strict;
  strict.min_corner_angle_deg = 89.0f;  // only right angles count
  AspectView b;
  ASSERT_TRUE(ComputeAspect(cube, ViewVector(55.0f, 30.0f), strict, &b).ok());
  EXPECT_LT(b.n_corners, 7);
}

TEST(Aspect, RefusesBadInput) {
  const Model& cube = ReferenceModel("cube");
  AspectView a;
  EXPECT_EQ(ComputeAspect(cube, Eigen::Vector3f::Zero(), AspectConfig{}, &a).code(),
            StatusCode::kInvalidArgument);
  AspectConfig bad;
  bad.distance_factor = 0.5f;
  EXPECT_EQ(ComputeAspect(cube, Eigen::Vector3f(0, 0, 1), bad, &a).code(),
            StatusCode::kInvalidArgument);
  Model broken = cube;
  broken.edges[0].a = 200;
  EXPECT_FALSE(ComputeAspect(broken, Eigen::Vector3f(0, 0, 1), AspectConfig{}, &a).ok());
  EXPECT_EQ(ComputeAspect(cube, Eigen::Vector3f(0, 0, 1), AspectConfig{}, nullptr).code(),
            StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace sh
