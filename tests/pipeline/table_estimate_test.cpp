// The table estimated from the objects resting on it: a known plane recovered from posed models
// with outliers (sunk, floating, tilted), refusals when no plane is shared, the slab filter.
#include "recog/pipeline/table_estimate.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "tables/table_file.hpp"

namespace sh {
namespace {

constexpr float kRadToDeg = 57.29578f;

// A table seen obliquely from 450 mm, as the recorded sets' cameras see theirs.
RigidTransform TestTable() {
  RigidTransform T;
  T.R = Eigen::AngleAxisf(2.2f, Eigen::Vector3f::UnitX()).toRotationMatrix() *
        Eigen::AngleAxisf(0.3f, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  T.t_mm = Eigen::Vector3f(5.0f, 20.0f, 450.0f);
  return T;
}

class TableEstimateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto t = OpenDefaultTable();
    ASSERT_TRUE(t.ok()) << t.status().message();
    table_ = *t;
    ASSERT_GE(table_.model_count(), 3u);
  }

  // Model m resting on face f of the table at (x, y) mm, turned by yaw about the table normal,
  // lifted by lift_mm (negative: sunk into the table).
  RecognizedObject Resting(uint16_t m, int f, float x, float y, float yaw, float lift_mm,
                           const RigidTransform& left_T_table = TestTable()) const {
    const Model& model = table_.model(m);
    // Rotate the face's outward normal onto the table's -z, then turn about z.
    const Eigen::Quaternionf down =
        Eigen::Quaternionf::FromTwoVectors(model.face_normal(f), -Eigen::Vector3f::UnitZ());
    const Eigen::Matrix3f table_R_model =
        Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()).toRotationMatrix() *
        down.toRotationMatrix();
    // The face's plane (normal . x = offset) lands at table height lift_mm.
    const float face_height = -model.faces[f].offset_mm;  // height of the face under the origin
    const Eigen::Vector3f table_t(x, y, lift_mm - face_height);
    RecognizedObject o;
    o.model = m;
    o.cam_T_model = left_T_table * RigidTransform{table_R_model, table_t};
    return o;
  }

  TableEstimate Estimate(const std::vector<RecognizedObject>& objects,
                         const TableEstimateConfig& config = {}) const {
    std::vector<const Model*> models;
    models.reserve(objects.size());
    for (const RecognizedObject& o : objects) models.push_back(&table_.model(o.model));
    TableEstimate e;
    EstimateTableFromObjects(objects.data(), models.data(), objects.size(), config, &e);
    return e;
  }

  TableView table_;
};

// Heights over the estimated table of every corner of the objects that rest on the true one.
TEST_F(TableEstimateTest, RecoversTheTableFromRestingObjectsDespiteOutliers) {
  std::vector<RecognizedObject> objects = {
      Resting(0, 0, -80, -60, 0.3f, 0),  Resting(1, 1, 70, -40, 1.2f, 0),
      Resting(2, 0, 10, 90, -0.7f, 0),   Resting(0, 2, -60, 80, 2.0f, 0),
      Resting(1, 0, 100, 60, 0.1f, -12),  // a wrong model half sunk into the table
      Resting(2, 1, -120, 0, 0.9f, 35)};  // stacked on something: floats
  // One object leaning: tipped by 20 deg about a horizontal axis.
  RecognizedObject leaning = Resting(0, 1, 0, -120, 0.4f, 15);
  leaning.cam_T_model.R =
      leaning.cam_T_model.R * Eigen::AngleAxisf(0.35f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  objects.push_back(leaning);

  const TableEstimate e = Estimate(objects);
  ASSERT_TRUE(e.accepted()) << TableEstimateOutcomeName(e.outcome);
  EXPECT_EQ(e.objects, 7u);
  EXPECT_EQ(e.resting, 4u);
  const RigidTransform truth = TestTable();
  const float normal_err =
      std::acos(std::min(1.0f, e.left_T_table.R.col(2).dot(truth.R.col(2)))) * kRadToDeg;
  EXPECT_LT(normal_err, 0.01f);
  // The frame is a rotation, its origin on the true plane.
  EXPECT_LT((e.left_T_table.R.transpose() * e.left_T_table.R - Eigen::Matrix3f::Identity())
                .cwiseAbs()
                .maxCoeff(),
            1e-5f);
  EXPECT_NEAR(e.left_T_table.R.determinant(), 1.0f, 1e-5f);
  EXPECT_NEAR(truth.R.col(2).dot(e.left_T_table.t_mm - truth.t_mm), 0.0f, 0.01f);
  EXPECT_LT(e.rms_mm, 0.01f);
  // Identity: the lowest corner of each resting object is at height 0 of the estimate, the sunk
  // one 12 mm under it, the floating one 35 mm over it.
  for (int i = 0; i < 4; ++i) {
    const RecognizedObject& o = objects[static_cast<size_t>(i)];
    EXPECT_NEAR(LowestCornerHeightMm(table_.model(o.model), o.cam_T_model, e.left_T_table), 0.0f,
                0.01f);
  }
  EXPECT_NEAR(
      LowestCornerHeightMm(table_.model(objects[4].model), objects[4].cam_T_model, e.left_T_table),
      -12.0f, 0.01f);
  EXPECT_NEAR(
      LowestCornerHeightMm(table_.model(objects[5].model), objects[5].cam_T_model, e.left_T_table),
      35.0f, 0.01f);
}

// Poses with the errors of accepted objects (0.3 deg, 0.3 mm) still give the plane closely.
TEST_F(TableEstimateTest, ToleratesPoseErrors) {
  std::vector<RecognizedObject> objects = {Resting(0, 0, -80, -60, 0.3f, 0.2f),
                                           Resting(1, 1, 70, -40, 1.2f, -0.3f),
                                           Resting(2, 0, 10, 90, -0.7f, 0.1f)};
  const float tilt[3] = {0.3f, -0.25f, 0.2f};
  for (size_t i = 0; i < objects.size(); ++i) {
    objects[i].cam_T_model.R =
        objects[i].cam_T_model.R *
        Eigen::AngleAxisf(tilt[i] / kRadToDeg, Eigen::Vector3f::UnitY()).toRotationMatrix();
  }
  const TableEstimate e = Estimate(objects);
  ASSERT_TRUE(e.accepted()) << TableEstimateOutcomeName(e.outcome);
  EXPECT_EQ(e.resting, 3u);
  const RigidTransform truth = TestTable();
  EXPECT_LT(std::acos(std::min(1.0f, e.left_T_table.R.col(2).dot(truth.R.col(2)))) * kRadToDeg,
            0.5f);
  EXPECT_NEAR(truth.R.col(2).dot(e.left_T_table.t_mm - truth.t_mm), 0.0f, 0.5f);
}

// No plane that two objects rest on: objects at different heights and tilts, or too few.
TEST_F(TableEstimateTest, RefusesScenesWithoutASharedPlane) {
  std::vector<RecognizedObject> scattered = {Resting(0, 0, -80, -60, 0.3f, 0),
                                             Resting(1, 1, 70, -40, 1.2f, 25),
                                             Resting(2, 0, 10, 90, -0.7f, -40)};
  scattered[2].cam_T_model.R = scattered[2].cam_T_model.R *
                               Eigen::AngleAxisf(0.5f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  TableEstimate e = Estimate(scattered);
  EXPECT_EQ(e.outcome, TableEstimateOutcome::kNoAgreement);
  EXPECT_EQ(e.resting, 1u);

  e = Estimate({Resting(0, 0, 0, 0, 0.0f, 0)});
  EXPECT_EQ(e.outcome, TableEstimateOutcome::kTooFewObjects);
  e = Estimate({});
  EXPECT_EQ(e.outcome, TableEstimateOutcome::kTooFewObjects);

  TableEstimateConfig off;
  off.enabled = false;
  e = Estimate({Resting(0, 0, -80, -60, 0.3f, 0), Resting(1, 1, 70, -40, 1.2f, 0)}, off);
  EXPECT_EQ(e.outcome, TableEstimateOutcome::kDisabled);

  // Three objects on one plane, but the camera only 50 mm over it (a plane seen nearly edge-on,
  // not a table under the cameras): refused.
  RigidTransform low = TestTable();
  const Eigen::Vector3f up = low.R.col(2);
  low.t_mm += (-up.dot(low.t_mm) - 50.0f) * up;
  std::vector<RecognizedObject> grazing = {Resting(0, 0, -80, -60, 0.3f, 0, low),
                                           Resting(1, 1, 70, -40, 1.2f, 0, low),
                                           Resting(2, 0, 10, 90, -0.7f, 0, low)};
  e = Estimate(grazing);
  EXPECT_EQ(e.outcome, TableEstimateOutcome::kNoAgreement);
  TableEstimateConfig lenient;
  lenient.min_height_mm = 10;
  lenient.max_view_angle_deg = 90;
  EXPECT_TRUE(Estimate(grazing, lenient).accepted());
}

TEST_F(TableEstimateTest, RefusesBadSettings) {
  TableEstimateConfig c;
  EXPECT_TRUE(CheckTableEstimateConfig(c).ok());
  c.tolerance_mm = 0;
  EXPECT_FALSE(CheckTableEstimateConfig(c).ok());
  c = {};
  c.tolerance_mm = std::nanf("");
  EXPECT_FALSE(CheckTableEstimateConfig(c).ok());
  c = {};
  c.min_objects = 0;
  EXPECT_FALSE(CheckTableEstimateConfig(c).ok());
  c = {};
  c.max_view_angle_deg = 95;
  EXPECT_FALSE(CheckTableEstimateConfig(c).ok());
}

// Points under the table or too far over it go; lines are clipped to the slab.
TEST(KeepOverTable, DropsAndClipsToTheSlab) {
  const RigidTransform T = TestTable();
  const auto at = [&](float x, float y, float h) { return T * Eigen::Vector3f(x, y, h); };
  Scene scene;
  for (float h : {-20.0f, -2.0f, 0.0f, 60.0f, 149.0f, 200.0f}) {
    ScenePoint p;
    p.p_mm = at(10, 10, h);
    ASSERT_TRUE(scene.points.push_back(p));
  }
  SceneLine inside, crossing, below, short_stub;
  inside.a_mm = at(0, 0, 1);
  inside.b_mm = at(50, 0, 1);
  inside.quality = 50;
  crossing.a_mm = at(0, 0, -53);  // -53..147 mm: 50 of 200 mm lie under the slab
  crossing.b_mm = at(0, 0, 147);
  crossing.quality = 200;
  below.a_mm = at(0, 0, -40);
  below.b_mm = at(60, 0, -40);
  short_stub.a_mm = at(0, 0, -30);  // only 5 mm of it in the slab
  short_stub.b_mm = at(0, 0, 2);
  for (const SceneLine& l : {inside, crossing, below, short_stub}) {
    ASSERT_TRUE(scene.lines.push_back(l));
  }
  const uint32_t dropped = KeepOverTable(T, 3.0f, 150.0f, 10.0f, &scene);
  EXPECT_EQ(dropped, 2u + 2u);  // points at -20 and 200, lines below and short_stub
  ASSERT_EQ(scene.points.size(), 4u);
  ASSERT_EQ(scene.lines.size(), 2u);
  const auto height = [&](const Eigen::Vector3f& p) { return T.R.col(2).dot(p - T.t_mm); };
  EXPECT_NEAR(height(scene.lines[0].a_mm), 1.0f, 1e-3f);
  EXPECT_NEAR(scene.lines[0].quality, 50.0f, 1e-3f);
  EXPECT_NEAR(std::min(height(scene.lines[1].a_mm), height(scene.lines[1].b_mm)), -3.0f, 1e-3f);
  EXPECT_NEAR(std::max(height(scene.lines[1].a_mm), height(scene.lines[1].b_mm)), 147.0f, 1e-3f);
  EXPECT_NEAR(scene.lines[1].quality, 150.0f, 1e-2f);
}

}  // namespace
}  // namespace sh
