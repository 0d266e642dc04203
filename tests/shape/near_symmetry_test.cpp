// Near symmetries by their geometry: the L bracket has one, half a turn about an axis in its
// profile plane that swaps its legs (50 and 45 mm, so a turned corner is a few millimetres from
// a corner); parts whose half turns are exact symmetries, or far from any, have none.
#include "recog/shape/near_symmetry.hpp"

#include <gtest/gtest.h>

#include <string>

#include "recog/geometry/rigid_transform.hpp"
#include "tables/model_files.hpp"
#include "tools/tablegen/model_symmetry.hpp"

namespace sh {
namespace {

Model ColourModel(const char* name) {
  Result<Model> m = LoadModelFile(std::string("models/colour/") + name + ".obj");
  EXPECT_TRUE(m.ok()) << m.status().message();
  if (!m.ok()) return Model{};
  StoreSymmetries(*m, FindSymmetries(*m));
  return *m;
}

TEST(NearSymmetry, TheBracketHasOneHalfTurnThatSwapsItsLegs) {
  const Model bracket = ColourModel("bracket");
  ASSERT_EQ(bracket.n_symmetries, 1);  // the identity alone
  const NearSymmetries near = FindNearSymmetries(bracket);
  ASSERT_EQ(near.n, 1);
  const Eigen::Matrix3f& R = near.R[0];
  EXPECT_NEAR(RotationAngleDeg(R), 180.0f, 10.0f);
  EXPECT_NEAR((R * R - Eigen::Matrix3f::Identity()).norm(), 0.0f, 0.3f);
  // The axis lies in the profile plane (z is the prism's depth), about along its bisector.
  const Eigen::Vector3f axis = (R + Eigen::Matrix3f::Identity()).col(0).normalized();
  const Eigen::Vector3f axis2 = (R + Eigen::Matrix3f::Identity()).col(1).normalized();
  const Eigen::Vector3f a = axis.allFinite() ? axis : axis2;
  EXPECT_LT(std::abs(a.z()), 0.01f);
  EXPECT_NEAR(std::abs(a.x()), std::abs(a.y()), 0.15f);
  // A turned corner is a few millimetres from a corner: the legs differ by 5 mm.
  EXPECT_GT(near.offset_mm[0], 1.0f);
  EXPECT_LT(near.offset_mm[0], 6.0f);
}

TEST(NearSymmetry, ExactOrFarHalfTurnsAreNotNear) {
  for (const char* name : {"cube", "can", "hexagon", "pentagon", "star", "wedge"}) {
    const Model m = ColourModel(name);
    EXPECT_EQ(FindNearSymmetries(m).n, 0) << name;
  }
  EXPECT_EQ(FindNearSymmetries(Model{}).n, 0);
}

TEST(NearSymmetry, AnUnlistedExactSymmetryIsNotNear) {
  Model bracket = ColourModel("bracket");
  Model cube = ColourModel("cube");
  cube.n_symmetries = 1;  // the group forgotten: its half turns are still exact
  EXPECT_EQ(FindNearSymmetries(cube).n, 0);
  // With a looser share nothing changes for the bracket's single near half turn.
  EXPECT_EQ(FindNearSymmetries(bracket, 0.3f).n, 1);
}

}  // namespace
}  // namespace sh
