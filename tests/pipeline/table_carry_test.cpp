// The plane carried between frames, by its identities: an estimate that agrees is carried after
// confirm_frames frames, one that disagrees starts the count again, a refused estimate changes
// nothing, misfitting frames drop the plane (back to estimating), a check estimate that agrees
// keeps it, and the carried plane is the mean of the agreeing estimates.
#include "recog/pipeline/table_carry.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

namespace sh {
namespace {

constexpr float kDegToRad = 0.017453292519943295f;

// A table seen obliquely from 450 mm, tilted by tilt_deg about its x axis and lifted by lift_mm
// along its normal.
RigidTransform Plane(float tilt_deg = 0.0f, float lift_mm = 0.0f) {
  RigidTransform T;
  T.R = Eigen::AngleAxisf(2.2f, Eigen::Vector3f::UnitX()).toRotationMatrix() *
        Eigen::AngleAxisf(0.3f, Eigen::Vector3f::UnitZ()).toRotationMatrix() *
        Eigen::AngleAxisf(tilt_deg * kDegToRad, Eigen::Vector3f::UnitX()).toRotationMatrix();
  T.t_mm = Eigen::Vector3f(5.0f, 20.0f, 450.0f);
  T.t_mm += lift_mm * T.R.col(2);
  return T;
}

TableEstimate Accepted(const RigidTransform& plane) {
  TableEstimate e;
  e.outcome = TableEstimateOutcome::kAccepted;
  e.left_T_table = plane;
  return e;
}

TableEstimate Refused() {
  TableEstimate e;
  e.outcome = TableEstimateOutcome::kTooFewObjects;
  return e;
}

TableCarryConfig Config() {
  TableCarryConfig c;
  c.enabled = true;
  c.confirm_frames = 3;
  c.misfit_frames = 2;
  c.check_every_frames = 0;
  return c;
}

// Confirms Plane() with confirm_frames agreeing estimates.
TableCarry Confirmed(const TableCarryConfig& c) {
  TableCarry carry;
  for (uint32_t i = 0; i < c.confirm_frames; ++i) carry.ObserveEstimate(c, Accepted(Plane()));
  return carry;
}

TEST(TableCarry, PlanesAgreeWithinBothTolerancesOnly) {
  EXPECT_TRUE(PlanesAgree(Plane(), Plane(), 2.0f, 1.0f));
  EXPECT_TRUE(PlanesAgree(Plane(), Plane(0.5f, 1.5f), 2.0f, 1.0f));
  EXPECT_FALSE(PlanesAgree(Plane(), Plane(0.0f, 2.5f), 2.0f, 1.0f));   // lifted
  EXPECT_FALSE(PlanesAgree(Plane(), Plane(0.0f, -2.5f), 2.0f, 1.0f));  // lowered
  EXPECT_FALSE(PlanesAgree(Plane(), Plane(1.5f), 2.0f, 1.0f));         // tilted
  // Agreement is symmetric.
  EXPECT_EQ(PlanesAgree(Plane(0.8f, 1.0f), Plane(), 2.0f, 1.0f),
            PlanesAgree(Plane(), Plane(0.8f, 1.0f), 2.0f, 1.0f));
  // A tilt about an axis through the origin moves far points: the other origin's height counts.
  RigidTransform far = Plane(0.9f);
  far.t_mm += 300.0f * far.R.col(1);
  EXPECT_FALSE(PlanesAgree(Plane(), far, 2.0f, 1.0f));
}

TEST(TableCarry, AnAgreeingPlaneIsCarriedAfterConfirmFrames) {
  const TableCarryConfig c = Config();
  TableCarry carry;
  EXPECT_EQ(carry.state(), TableCarryState::kSearching);
  EXPECT_EQ(carry.Next(c), TableCarryUse::kEstimate);
  for (uint32_t i = 1; i <= c.confirm_frames; ++i) {
    carry.ObserveEstimate(c, Accepted(Plane(0.1f * float(i), 0.3f * float(i))));
    EXPECT_EQ(carry.agreeing(), i);
    const bool done = i == c.confirm_frames;
    EXPECT_EQ(carry.trusted(), done) << i;
    EXPECT_EQ(carry.Next(c), done ? TableCarryUse::kCarry : TableCarryUse::kEstimate) << i;
  }
  // The carried plane agrees with every estimate that confirmed it.
  for (uint32_t i = 1; i <= c.confirm_frames; ++i) {
    EXPECT_TRUE(
        PlanesAgree(carry.left_T_table(), Plane(0.1f * float(i), 0.3f * float(i)), 2.0f, 1.0f));
  }
  // Its frame stays a rotation.
  const Eigen::Matrix3f R = carry.left_T_table().R;
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3f::Identity()).norm(), 1e-5f);
  EXPECT_NEAR(R.determinant(), 1.0f, 1e-5f);
}

TEST(TableCarry, TheCarriedPlaneIsTheMeanOfTheAgreeingEstimates) {
  const TableCarryConfig c = Config();
  TableCarry carry;
  carry.ObserveEstimate(c, Accepted(Plane(0.0f, -0.9f)));
  carry.ObserveEstimate(c, Accepted(Plane(0.0f, 0.0f)));
  carry.ObserveEstimate(c, Accepted(Plane(0.0f, 0.9f)));
  ASSERT_TRUE(carry.trusted());
  // Heights -0.9, 0 and +0.9 mm along one normal: the mean is the middle plane.
  EXPECT_TRUE(PlanesAgree(carry.left_T_table(), Plane(), 1e-3f, 0.05f));
}

TEST(TableCarry, ADisagreeingEstimateStartsTheCountAgain) {
  const TableCarryConfig c = Config();
  TableCarry carry;
  carry.ObserveEstimate(c, Accepted(Plane()));
  carry.ObserveEstimate(c, Accepted(Plane()));
  ASSERT_EQ(carry.agreeing(), 2u);
  carry.ObserveEstimate(c, Accepted(Plane(0.0f, 10.0f)));  // 10 mm higher: another plane
  EXPECT_EQ(carry.state(), TableCarryState::kConfirming);
  EXPECT_EQ(carry.agreeing(), 1u);
  EXPECT_TRUE(PlanesAgree(carry.left_T_table(), Plane(0.0f, 10.0f), 1e-3f, 0.05f));
  carry.ObserveEstimate(c, Accepted(Plane(0.0f, 10.0f)));
  EXPECT_FALSE(carry.trusted());
  carry.ObserveEstimate(c, Accepted(Plane(0.0f, 10.0f)));
  EXPECT_TRUE(carry.trusted());
  EXPECT_TRUE(PlanesAgree(carry.left_T_table(), Plane(0.0f, 10.0f), 1e-3f, 0.05f));
}

TEST(TableCarry, ARefusedEstimateChangesNothing) {
  const TableCarryConfig c = Config();
  TableCarry carry;
  carry.ObserveEstimate(c, Refused());
  EXPECT_EQ(carry.state(), TableCarryState::kSearching);
  carry.ObserveEstimate(c, Accepted(Plane()));
  carry.ObserveEstimate(c, Refused());  // an empty belt between two parts
  EXPECT_EQ(carry.agreeing(), 1u);
  carry.ObserveEstimate(c, Accepted(Plane()));
  carry.ObserveEstimate(c, Accepted(Plane()));
  EXPECT_TRUE(carry.trusted());
}

TEST(TableCarry, FramesThatFitKeepThePlane) {
  const TableCarryConfig c = Config();
  TableCarry carry = Confirmed(c);
  ASSERT_TRUE(carry.trusted());
  for (int i = 0; i < 20; ++i) {
    carry.ObserveCarried(c, 4, 3, 2);  // most objects rest on it
    carry.ObserveCarried(c, 1, 0, 3);  // one leaning object: too few to judge
    carry.ObserveCarried(c, 0, 0, 0);  // an empty belt
  }
  EXPECT_TRUE(carry.trusted());
  EXPECT_EQ(carry.Next(c), TableCarryUse::kCarry);
  EXPECT_EQ(carry.misfits(), 0u);
  EXPECT_EQ(carry.drops(), 0u);
}

TEST(TableCarry, AMisfitIsCheckedByAnEstimateThatKeepsAnAgreeingPlane) {
  const TableCarryConfig c = Config();
  TableCarry carry = Confirmed(c);
  carry.ObserveCarried(c, 4, 1, 0);  // three of four objects off the plane
  EXPECT_EQ(carry.misfits(), 1u);
  EXPECT_TRUE(carry.trusted());
  EXPECT_EQ(carry.Next(c), TableCarryUse::kEstimate);  // checked by an estimate
  carry.ObserveEstimate(c, Refused());                 // no evidence: check again
  EXPECT_EQ(carry.Next(c), TableCarryUse::kEstimate);
  carry.ObserveEstimate(c, Accepted(Plane(0.0f, 0.5f)));
  EXPECT_EQ(carry.misfits(), 0u);
  EXPECT_EQ(carry.Next(c), TableCarryUse::kCarry);
}

TEST(TableCarry, AMovedTableIsDroppedAndTheNewOneConfirmed) {
  const TableCarryConfig c = Config();
  TableCarry carry = Confirmed(c);
  // The belt was raised by 12 mm: the objects float over the carried plane.
  carry.ObserveCarried(c, 3, 0, 0);
  EXPECT_EQ(carry.Next(c), TableCarryUse::kEstimate);
  const RigidTransform raised = Plane(0.0f, 12.0f);
  carry.ObserveEstimate(c, Accepted(raised));  // second misfit in a row: dropped
  EXPECT_EQ(carry.drops(), 1u);
  EXPECT_EQ(carry.state(), TableCarryState::kConfirming);
  EXPECT_EQ(carry.agreeing(), 1u);
  EXPECT_EQ(carry.Next(c), TableCarryUse::kEstimate);  // back to estimating
  carry.ObserveEstimate(c, Accepted(raised));
  carry.ObserveEstimate(c, Accepted(raised));
  EXPECT_TRUE(carry.trusted());
  EXPECT_TRUE(PlanesAgree(carry.left_T_table(), raised, 1e-3f, 0.05f));
}

TEST(TableCarry, HypothesesSinkingIntoAPlaneWithNothingOnItDropIt) {
  TableCarryConfig c = Config();
  c.misfit_frames = 1;
  TableCarry carry = Confirmed(c);
  carry.ObserveCarried(c, 0, 0, c.max_sunk);  // at the limit: fits
  EXPECT_TRUE(carry.trusted());
  carry.ObserveCarried(c, 0, 0, c.max_sunk + 1);  // a plane over the real table
  EXPECT_EQ(carry.state(), TableCarryState::kSearching);
  EXPECT_EQ(carry.drops(), 1u);
  EXPECT_EQ(carry.Next(c), TableCarryUse::kEstimate);
}

TEST(TableCarry, TheCarriedPlaneIsCheckedPeriodically) {
  TableCarryConfig c = Config();
  c.check_every_frames = 5;
  TableCarry carry = Confirmed(c);
  for (uint32_t i = 0; i < c.check_every_frames; ++i) {
    ASSERT_EQ(carry.Next(c), TableCarryUse::kCarry) << i;
    carry.ObserveCarried(c, 3, 3, 0);
  }
  EXPECT_EQ(carry.Next(c), TableCarryUse::kEstimate);
  carry.ObserveEstimate(c, Accepted(Plane()));
  EXPECT_EQ(carry.Next(c), TableCarryUse::kCarry);
  EXPECT_EQ(carry.carried_frames(), 0u);
}

TEST(TableCarry, ConfigurationsOutOfRangeAreRefused) {
  EXPECT_TRUE(CheckTableCarryConfig(TableCarryConfig{}).ok());
  TableCarryConfig c;
  c.confirm_frames = 0;
  EXPECT_FALSE(CheckTableCarryConfig(c).ok());
  c = TableCarryConfig{};
  c.tolerance_mm = std::nanf("");
  EXPECT_FALSE(CheckTableCarryConfig(c).ok());
  c = TableCarryConfig{};
  c.tolerance_deg = 0;
  EXPECT_FALSE(CheckTableCarryConfig(c).ok());
  c = TableCarryConfig{};
  c.min_resting_share = 1.5f;
  EXPECT_FALSE(CheckTableCarryConfig(c).ok());
}

}  // namespace
}  // namespace sh
