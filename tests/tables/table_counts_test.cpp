// The preprocessing must reproduce the thesis's model-basis and entry counts (tables 2.1, 5.2,
// 5.3) for the six reference objects.
#include <gtest/gtest.h>

#include "tables/model_files.hpp"
#include "tools/tablegen/model_symmetry.hpp"
#include "tools/tablegen/table_builder.hpp"

namespace sh {
namespace {

std::vector<Model> ReferenceModels() {
  std::vector<Model> models;
  const Status s = LoadModelFolder("models", &models);
  EXPECT_TRUE(s.ok()) << s.message();
  return models;
}

TableBuildReport Build(HashFunction hf) {
  TableBuildOptions options;
  options.hash_function = hf;
  TableBuildReport report;
  const auto blob = BuildTableBlob(ReferenceModels(), options, &report);
  EXPECT_TRUE(blob.ok()) << blob.status().message();
  return report;
}

TEST(ModelSymmetry, GroupOrdersMatchTheReferenceObjects) {
  const std::vector<Model> models = ReferenceModels();
  const size_t expected[] = {8, 12, 6, 10, 10, 2};  // D4, D6, D3, D5, D5, C2
  ASSERT_EQ(models.size(), 6u);
  for (size_t i = 0; i < models.size(); ++i) {
    const auto group = FindSymmetries(models[i]);
    EXPECT_EQ(group.size(), expected[i]) << models[i].name;
    ASSERT_FALSE(group.empty());
    EXPECT_TRUE(group[0].R.isIdentity(1e-5f)) << "identity first";
  }
}

TEST(ModelSymmetry, TheCanKeepsTheWholeDihedralGroupOfItsFortyEightSides) {
  Result<Model> can = LoadModelFile("models/colour/can.obj");
  ASSERT_TRUE(can.ok()) << can.status().message();
  EXPECT_EQ(can->n_corners, 96);
  EXPECT_EQ(can->n_edges, 144);
  EXPECT_EQ(can->n_faces, 50);
  const auto group = FindSymmetries(*can);
  EXPECT_EQ(group.size(), 96u);  // D48: 48 turns about the axis, 48 half-turns across it
  StoreSymmetries(*can, group);
  EXPECT_EQ(can->n_symmetries, 96);
  for (int k = 0; k < can->n_symmetries; ++k) {
    const Eigen::Matrix3f R = can->symmetry(k);
    EXPECT_TRUE((R * R.transpose()).isIdentity(1e-4f)) << k;
    EXPECT_NEAR(R.determinant(), 1.0f, 1e-4f) << k;
  }
}

TEST(TableCounts, ThreePointBasesMatchTheThesis) {
  for (HashFunction hf : {HashFunction::kThreePointsFirst, HashFunction::kThreePointsCentroid}) {
    const TableBuildReport r = Build(hf);
    const uint32_t expected[] = {42, 110, 20, 684, 72, 168};
    ASSERT_EQ(r.per_model.size(), 6u);
    for (size_t i = 0; i < 6; ++i)
      EXPECT_EQ(r.per_model[i].bases, expected[i]) << r.per_model[i].model;
    EXPECT_EQ(r.point_entries, 15328u);
    EXPECT_EQ(r.line_entries, 26280u);
  }
}

TEST(TableCounts, LinePointBasesMatchTheThesis) {
  for (HashFunction hf : {HashFunction::kLinePointFoot, HashFunction::kLinePointMidway}) {
    const TableBuildReport r = Build(hf);
    const uint32_t expected[] = {18, 30, 12, 100, 24, 72};
    ASSERT_EQ(r.per_model.size(), 6u);
    for (size_t i = 0; i < 6; ++i)
      EXPECT_EQ(r.per_model[i].bases, expected[i]) << r.per_model[i].model;
    EXPECT_EQ(r.point_entries, 3136u);
    EXPECT_EQ(r.line_entries, 4832u);
  }
}

TEST(TableCounts, TwoLineBasesStoreAllFeatures) {
  const TableBuildReport r = Build(HashFunction::kTwoLines);
  const std::vector<Model> models = ReferenceModels();
  for (size_t i = 0; i < models.size(); ++i) {
    EXPECT_GT(r.per_model[i].bases, 0u);
    EXPECT_EQ(r.per_model[i].point_entries, r.per_model[i].bases * models[i].n_corners);
    EXPECT_EQ(r.per_model[i].line_entries, r.per_model[i].bases * models[i].n_edges);
  }
}

}  // namespace
}  // namespace sh
