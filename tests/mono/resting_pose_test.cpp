// Objects resting on the table: stable faces of the convex hull, resting poses and their
// recovery from a free pose or from two corners on their viewing rays.
#include "recog/mono/resting_pose.hpp"

#include <gtest/gtest.h>

#include <random>

#include "tests/mono/mono_fixtures.hpp"

namespace sh {
namespace {

using testing::ReferenceModel;

// Camera 290 mm above the table, looking down 51.5 degrees from its normal.
TablePlane TiltedTable() { return testing::ThesisTable(); }

TEST(StableFaces, HullFacesThatHoldTheCentreOfMass) {
  // Prisms rest on their caps and sides; the star rests on its caps and on pairs of points
  // (hull faces that are no model face); the trapezium on all six faces.
  const struct {
    const char* name;
    int faces;
  } expected[] = {{"cube", 6},     {"hexagon", 8}, {"wedge", 5},
                  {"pentagon", 7}, {"star", 7},    {"trapezium", 6}};
  for (const auto& e : expected) {
    StableFaces faces;
    ASSERT_TRUE(ComputeStableFaces(ReferenceModel(e.name), 0.5f, &faces).ok());
    EXPECT_EQ(faces.count, e.faces) << e.name;
    for (int f = 0; f < faces.count; ++f) {
      EXPECT_NEAR(faces.faces[f].normal_model.norm(), 1.0f, 1e-4f);
      EXPECT_GT(faces.faces[f].area_mm2, 0.0f);
      // Every corner lies on or behind the face's plane (a hull face).
      const Model& m = ReferenceModel(e.name);
      for (int i = 0; i < m.n_corners; ++i) {
        EXPECT_LE(faces.faces[f].normal_model.dot(m.corner(i)), faces.faces[f].offset_mm + 1e-3f);
      }
    }
  }
}

TEST(StableFaces, CentreOfMassOfTheTrapezium) {
  // The vertex centroid of an isosceles trapezium prism (sides 50 / 25, 25 apart) lies half
  // way between the parallel sides; its centre of mass lies nearer the long side.
  const Model& m = ReferenceModel("trapezium");
  const Eigen::Vector3f vertex = ModelCentroid(m);
  const Eigen::Vector3f mass = SolidCentroid(m);
  EXPECT_GT((vertex - mass).norm(), 1.0f);
  EXPECT_LT((vertex - mass).norm(), 2.0f);
  // The cube's coincide.
  const Model& cube = ReferenceModel("cube");
  EXPECT_LT((ModelCentroid(cube) - SolidCentroid(cube)).norm(), 1e-3f);
}

TEST(RestingPose, LiesOnTheTableAndIsRecoveredFromNearbyPoses) {
  const TablePlane table = TiltedTable();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (const char* name : {"cube", "star", "trapezium"}) {
    const Model& m = ReferenceModel(name);
    StableFaces faces;
    ASSERT_TRUE(ComputeStableFaces(m, 0.5f, &faces).ok());
    for (int f = 0; f < faces.count; ++f) {
      const RestingPose truth{f, 3.0f * u(rng), 60.0f * u(rng), 60.0f * u(rng)};
      const RigidTransform cam_T_model = RestingTransform(table, faces, truth);
      // Corners on or above the table, the face's corners on it.
      const RigidTransform table_T_model = table.cam_T_table.Inverse() * cam_T_model;
      float lowest = 1e9f;
      for (int i = 0; i < m.n_corners; ++i) {
        lowest = std::min(lowest, (table_T_model * m.corner(i)).z());
      }
      EXPECT_NEAR(lowest, 0.0f, 1e-3f) << name << " face " << f;
      // A pose tilted by a few degrees and moved along the viewing ray snaps back.
      RigidTransform disturbed = cam_T_model;
      disturbed.R = Eigen::AngleAxisf(0.05f, Eigen::Vector3f(1, 2, 0).normalized()) * disturbed.R;
      disturbed.t_mm *= 1.1f;
      RestingPose back;
      float tilt = 0;
      ASSERT_TRUE(NearestRestingPose(table, faces, disturbed, 20.0f, &back, &tilt));
      EXPECT_EQ(back.face, f);
      EXPECT_LT(tilt, 5.0f);
      const RigidTransform snapped = RestingTransform(table, faces, back);
      EXPECT_LT(RotationAngleDeg(snapped.R.transpose() * cam_T_model.R), 3.0f);
      // The origin stays on its viewing ray: the position error is what the tilt moves it.
      EXPECT_LT((snapped.t_mm - cam_T_model.t_mm).norm(), 5.0f);
    }
  }
}

TEST(RestingPose, TwoCornersOnTheirRaysGiveThePose) {
  const TablePlane table = TiltedTable();
  const Model& m = ReferenceModel("trapezium");
  StableFaces faces;
  ASSERT_TRUE(ComputeStableFaces(m, 0.5f, &faces).ok());
  int checked = 0;
  for (int f = 0; f < faces.count; ++f) {
    const RestingPose truth{f, 0.8f, -25.0f, 40.0f};
    const RigidTransform cam_T_model = RestingTransform(table, faces, truth);
    for (int a = 0; a < m.n_corners; ++a) {
      for (int b = a + 1; b < m.n_corners; ++b) {
        const Eigen::Vector3f ray_a = cam_T_model * m.corner(a);
        const Eigen::Vector3f ray_b = cam_T_model * m.corner(b);
        RestingPose pose;
        float ratio = 0;
        if (!RestingPoseFromCorners(table, faces, f, m.corner(a), m.corner(b), ray_a, ray_b, 5.0f,
                                    &pose, &ratio)) {
          continue;  // corners above each other: no heading from them
        }
        ++checked;
        EXPECT_NEAR(ratio, 1.0f, 1e-3f);
        const RigidTransform found = RestingTransform(table, faces, pose);
        EXPECT_LT((found.t_mm - cam_T_model.t_mm).norm(), 0.05f);
        EXPECT_LT(RotationAngleDeg(found.R.transpose() * cam_T_model.R), 0.05f);
      }
    }
    // On the wrong face the corners' heights differ and the distance on the table disagrees.
    const int other = (f + 1) % faces.count;
    const Eigen::Vector3f ray_a = cam_T_model * m.corner(0);
    const Eigen::Vector3f ray_b = cam_T_model * m.corner(2);
    RestingPose pose;
    float ratio = 1.0f;
    if (RestingPoseFromCorners(table, faces, other, m.corner(0), m.corner(2), ray_a, ray_b, 5.0f,
                               &pose, &ratio)) {
      EXPECT_GT(std::fabs(ratio - 1.0f), 1e-3f);
    }
  }
  EXPECT_GT(checked, 50);
}

TEST(RestingPose, RefusesWhatCannotRest) {
  StableFaces none;
  RestingPose pose;
  EXPECT_FALSE(NearestRestingPose(TiltedTable(), none, RigidTransform::Identity(), 90.0f, &pose));
  Model broken = ReferenceModel("cube");
  broken.faces[0].vertices[0] = 120;
  StableFaces faces;
  EXPECT_FALSE(ComputeStableFaces(broken, 0.5f, &faces).ok());
}

}  // namespace
}  // namespace sh
