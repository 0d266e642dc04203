// The project's OBJ models, parsed by ParseObjModel, go through hidden-line computation and
// verification like the records built in code.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "recog/model/obj_model.hpp"
#include "recog/verify/verify.hpp"
#include "tests/support/edge_scene.hpp"
#include "tests/support/test_models.hpp"

namespace sh {
namespace {

using testing::AxisAngleDeg;

constexpr double kSinHalfDegree = 0.0087265;

class ObjModelsTest : public ::testing::TestWithParam<const char*> {
 protected:
  StereoCalibration calib = testing::TestCalibration();
};

TEST_P(ObjModelsTest, HiddenLinesAgreeWithBruteForce) {
  Result<Model> model = testing::LoadReferenceModel(GetParam());
  ASSERT_TRUE(model.ok()) << model.status().message();
  ASSERT_TRUE(CheckModel(*model).ok());
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_real_distribution<float> angle(0.0f, 180.0f);
  int samples = 0, mismatches = 0;
  for (int trial = 0; trial < 10; ++trial) {
    // One draw a statement: the order in which a call's arguments are evaluated differs between
    // compilers, and so would the poses.
    const float ax = unit(rng), ay = unit(rng), az = unit(rng);
    const float angle_deg = angle(rng);
    const float tx = 30 * unit(rng), ty = 30 * unit(rng), tz = 450 + 50 * unit(rng);
    const PosedModel object{&*model, {AxisAngleDeg({ax, ay, az}, angle_deg), {tx, ty, tz}}};
    for (const ViewCamera& view : {LeftView(calib), RightView(calib)}) {
      VisibleEdgeSet set;
      ASSERT_TRUE(ComputeVisibleEdges(view, object, nullptr, 0, 1.0f, 1.0f, &set).ok());
      EXPECT_GT(set.n_edges, 0);
      for (int k = 0; k < set.n_edges; ++k) {
        const VisibleEdge& ve = set.edges[k];
        for (int i = 0; i < ve.n_samples; ++i) {
          const Eigen::Vector3f x = PointAtImageFraction(ve, SampleImageFraction(i, ve.n_samples));
          ++samples;
          // Faces within half a degree of edge-on do not hide (see BruteForceVisible).
          if (testing::BruteForceVisible(view, {object}, x.cast<double>(), kOcclusionToleranceMm,
                                         kSinHalfDegree) != IsSampleVisible(ve, i)) {
            ++mismatches;
          }
        }
      }
    }
  }
  EXPECT_LE(mismatches * 1000, samples) << mismatches << " of " << samples;
}

// The edge-pixel verifier is the polyhedral path's: a can's 48 creases 3 mm apart confirm a
// shifted pose too, so it runs on the six reference polyhedra only.
class ObjPolyhedraTest : public ObjModelsTest {};

TEST_P(ObjPolyhedraTest, TruePoseVerifiesAndShiftedPoseDoesNot) {
  Result<Model> model = testing::LoadReferenceModel(GetParam());
  ASSERT_TRUE(model.ok()) << model.status().message();
  const PosedModel truth{&*model, {AxisAngleDeg({1, 0.4f, 0.2f}, 130), {-20, 15, 470}}};
  const testing::EdgeMapBuffer left = testing::RenderEdgeMap(LeftView(calib), {truth});
  const testing::EdgeMapBuffer right = testing::RenderEdgeMap(RightView(calib), {truth});
  Result<VerifyResult> r = VerifyHypothesis(calib, left.const_view(), right.const_view(), truth,
                                            nullptr, 0, VerifyConfig{});
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(r->accepted) << VerifyReasonName(r->reason);
  EXPECT_GT(r->score_left, 0.85f);
  EXPECT_GT(r->score_right, 0.85f);
  PosedModel moved = truth;
  moved.cam_T_model.t_mm.x() += 10.0f;
  r = VerifyHypothesis(calib, left.const_view(), right.const_view(), moved, nullptr, 0,
                       VerifyConfig{});
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->accepted);
}

INSTANTIATE_TEST_SUITE_P(Models, ObjModelsTest,
                         ::testing::Values("cube", "hexagon", "pentagon", "star", "trapezium",
                                           "wedge", "colour/can", "colour/bracket"));
INSTANTIATE_TEST_SUITE_P(Models, ObjPolyhedraTest,
                         ::testing::Values("cube", "hexagon", "pentagon", "star", "trapezium",
                                           "wedge", "colour/bracket"));

TEST(ObjStarTest, SameTopologyAsTheRecordBuiltInCode) {
  Result<Model> parsed = testing::LoadReferenceModel("star");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  const Model built = testing::StarModel();
  EXPECT_EQ(parsed->n_corners, built.n_corners);
  EXPECT_EQ(parsed->n_edges, built.n_edges);
  EXPECT_EQ(parsed->n_faces, built.n_faces);
}

}  // namespace
}  // namespace sh
