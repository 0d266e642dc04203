#include "recog/hashing/pose_refine.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <memory>

#include "recog/hashing/scene_grid.hpp"
#include "tests/support/tables_fixture.hpp"

namespace sh {
namespace {

using testing::ModelsOf;

TEST(SegmentLineDistance, IsThePointToLineDistanceAveragedOverTheSegment) {
  // Numerical average of the squared distance from points of the segment to the line.
  const Eigen::Vector3f centre(3, 4, 1), dir = Eigen::Vector3f(1, 2, 0.5f).normalized();
  const Eigen::Vector3f s(0, 0, 0), v = Eigen::Vector3f(0.2f, 1, 0.1f).normalized();
  const float length = 30.0f;
  double sum = 0;
  const int n = 10000;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3f x = centre + ((i + 0.5f) / n - 0.5f) * length * dir;
    const Eigen::Vector3f w = x - s;
    sum += (w - w.dot(v) * v).squaredNorm();
  }
  EXPECT_NEAR(SegmentLineDistance2(centre, dir, length, s, v), sum / n, 1e-2);
}

// A segment on a line far from the line's support point: the difference of two large squares
// would cancel to a value of either sign; the distance stays a small non-negative number.
TEST(SegmentLineDistance, StaysNonNegativeFarAlongTheLine) {
  const Eigen::Vector3f v = Eigen::Vector3f(0.3f, -0.2f, 0.93f).normalized();
  const Eigen::Vector3f s(-40.0f, 25.0f, 300.0f);
  int negative = 0;
  for (int i = 0; i < 1000; ++i) {
    const float along_mm = 500.0f + 1.37f * float(i);
    const Eigen::Vector3f centre =
        s + along_mm * v + Eigen::Vector3f(1e-3f, -1e-3f, 0) * float(i % 7);
    const float d2 = SegmentLineDistance2(centre, v, 25.0f, s, v);
    if (!(d2 >= 0.0f)) ++negative;
    EXPECT_LT(d2, 0.01f) << i;
  }
  EXPECT_EQ(negative, 0);
}

class PoseRefineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto view = OpenDefaultTable();
    ASSERT_TRUE(view.ok());
    models_ = ModelsOf(*view);
    grid_ = std::make_unique<SceneGrid>();
  }
  // The scene holds exactly the model's features at `truth`.
  void MakeScene(const Model& m, const RigidTransform& truth) {
    scene_ = std::make_unique<Scene>();
    for (int i = 0; i < m.n_corners; ++i) {
      ScenePoint p;
      p.p_mm = truth * m.corner(i);
      ASSERT_TRUE(scene_->points.push_back(p));
    }
    for (int e = 0; e < m.n_edges; ++e) {
      SceneLine l;
      l.a_mm = truth * m.corner(m.edges[e].a);
      l.b_mm = truth * m.corner(m.edges[e].b);
      ASSERT_TRUE(scene_->lines.push_back(l));
    }
    std::vector<Eigen::Vector3f> positions;
    for (const auto& p : scene_->points) positions.push_back(p.p_mm);
    grid_->Build(positions.data(), int(positions.size()), 5.0f);
    active_points_.assign(scene_->points.size(), 1);
    active_lines_.assign(scene_->lines.size(), 1);
  }
  RefineInput Input(const Model& m) {
    RefineInput in;
    in.model = &m;
    in.scene = scene_.get();
    in.point_active = active_points_.data();
    in.line_active = active_lines_.data();
    in.point_grid = grid_.get();
    return in;
  }
  std::vector<Model> models_;
  std::unique_ptr<Scene> scene_;
  std::unique_ptr<SceneGrid> grid_;
  std::vector<uint8_t> active_points_, active_lines_;
};

TEST_F(PoseRefineTest, ConvergesToTheTruePoseFromAPerturbedStart) {
  for (const Model& m : models_) {
    const RigidTransform truth{
        Eigen::AngleAxisf(0.7f, Eigen::Vector3f(1, 2, 3).normalized()).toRotationMatrix(),
        {20, -40, 520}};
    MakeScene(m, truth);
    RigidTransform start = truth;
    start.R = Eigen::AngleAxisf(0.05f, Eigen::Vector3f(0, 1, 1).normalized()) * truth.R;  // 2.9 deg
    start.t_mm += Eigen::Vector3f(1.5f, -1.0f, 1.0f);
    const RefineResult r = RefinePose(Input(m), start, RefineConfig{});
    EXPECT_LT((r.cam_T_model.t_mm - truth.t_mm).norm(), 1e-2f) << m.name;
    EXPECT_LT(RotationAngleDeg(r.cam_T_model.R.transpose() * truth.R), 1e-2f) << m.name;
    EXPECT_EQ(r.matches.matched_points, m.n_corners) << m.name;
    EXPECT_EQ(r.matches.matched_lines, m.n_edges) << m.name;
  }
}

TEST_F(PoseRefineTest, LinesAloneDetermineThePose) {
  const Model& m = models_[0];  // cube
  const RigidTransform truth{Eigen::Matrix3f::Identity(), {0, 0, 500}};
  MakeScene(m, truth);
  std::fill(active_points_.begin(), active_points_.end(), 0);
  RigidTransform start = truth;
  start.t_mm += Eigen::Vector3f(1.0f, 1.0f, -1.0f);
  const RefineResult r = RefinePose(Input(m), start, RefineConfig{});
  EXPECT_EQ(r.matches.matched_points, 0);
  EXPECT_LT((r.cam_T_model.t_mm - truth.t_mm).norm(), 1e-2f);
}

}  // namespace
}  // namespace sh
