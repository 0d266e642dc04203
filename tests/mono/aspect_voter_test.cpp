// The 2-D vote: an aspect seen exactly votes fully for its own bases; metric correction makes
// the vote independent of the basis scale; one vote per model entry per scene basis.
#include "recog/mono/aspect_voter.hpp"

#include <gtest/gtest.h>

#include "tests/mono/mono_fixtures.hpp"

namespace sh {
namespace {

using testing::BuildTable;
using testing::ReferenceModel;

struct AspectScene {
  std::vector<ScenePoint2d> points;
  std::vector<SceneLine2d> lines;
};

// The aspect's own features scaled to `scale_px` per normalised unit and rotated.
AspectScene SceneOfAspect(const AspectView& a, float scale_px, float angle_rad,
                          const Eigen::Vector2f& shift) {
  AspectScene s;
  const Eigen::Matrix2f R = Eigen::Rotation2Df(angle_rad).toRotationMatrix();
  for (int i = 0; i < a.n_corners; ++i)
    s.points.push_back({R * (scale_px * a.corners[i].xy) + shift});
  for (int k = 0; k < a.n_segments; ++k) {
    const Eigen::Vector2f p = R * (scale_px * a.segments[k].a) + shift;
    const Eigen::Vector2f q = R * (scale_px * a.segments[k].b) + shift;
    SceneLine2d l;
    l.point = p;
    l.dir = (q - p).normalized();
    l.t1 = (q - p).norm();
    s.lines.push_back(l);
  }
  return s;
}

// Every third aspect's every basis of `table` (built from `model`), seen at two scales and an
// arbitrary rotation, votes fully (2: points and lines) for itself; returns the bases checked.
int CheckExactAspectsVoteFully(const Model& model, const testing::BuiltAspectTable& table,
                               AspectVoter& voter) {
  AspectConfig ac;
  int checked = 0;
  for (uint32_t a = 0; a < table.view.aspect_count(); a += 3) {
    const AspectRecord& rec = table.view.aspect(a);
    AspectView view;
    EXPECT_TRUE(ComputeAspect(model,
                              Eigen::Vector3f(rec.dir_model[0], rec.dir_model[1], rec.dir_model[2]),
                              ac, &view)
                    .ok());
    for (float scale : {600.0f, 1500.0f}) {
      const AspectScene s = SceneOfAspect(view, scale, 0.6f, {40.0f, -25.0f});
      for (uint32_t b = rec.first_basis; b < rec.first_basis + rec.n_bases; ++b) {
        const AspectBasis& basis = table.view.basis(b);
        int i = -1, j = -1;
        for (int k = 0; k < view.n_corners; ++k) {
          if (view.corners[k].corner == basis.corners[0]) i = k;
          if (view.corners[k].corner == basis.corners[1]) j = k;
        }
        if (i < 0 || j < 0) {
          ADD_FAILURE() << "aspect " << a << " basis " << b << " corners not in the view";
          continue;
        }
        AspectHypothesis h[1];
        testing::VotePair(voter, s.points, s.lines, i, j, 0.0f, h, 1);
        EXPECT_NEAR(voter.LastVote(b), 2.0f, 0.01f) << "aspect " << a << " basis " << b;
        ++checked;
      }
    }
  }
  return checked;
}

TEST(AspectVoter, ExactAspectVotesFullyForItsOwnBasis) {
  const Model& cube = ReferenceModel("cube");
  const testing::ModelVoter v = testing::VoterOf(cube);
  EXPECT_GT(CheckExactAspectsVoteFully(cube, *v.table, *v.voter), 50);
}

// A voter set up again for another table takes that table's counters: its votes are those of a
// voter set up for it alone.
TEST(AspectVoter, InitForAnotherTableVotesAsAFreshVoter) {
  const Model& cube = ReferenceModel("cube");
  const Model& wedge = ReferenceModel("wedge");
  const testing::ModelVoter on_wedge = testing::VoterOf(wedge);
  const testing::ModelVoter on_cube = testing::VoterOf(cube);
  AspectVoter& voter = *on_wedge.voter;  // set up for the wedge first
  ASSERT_TRUE(voter.Init(on_cube.table->view, VoterConfig{}).ok());
  EXPECT_GT(CheckExactAspectsVoteFully(cube, *on_cube.table, voter), 50);
  ASSERT_TRUE(voter.Init(on_wedge.table->view, VoterConfig{}).ok());
  EXPECT_GT(CheckExactAspectsVoteFully(wedge, *on_wedge.table, voter), 10);
}

// One aspect basis and a scene built from its own corners and segments.
struct OneBasis {
  std::unique_ptr<testing::BuiltAspectTable> table;
  std::unique_ptr<AspectVoter> voter;
  AspectView view;
  uint32_t basis = 0;
  int i = -1, j = -1;  // the basis corners among the aspect's corners
};

OneBasis MakeOneBasis(float sigma_px) {
  OneBasis o;
  const Model& cube = ReferenceModel("cube");
  AspectBuildOptions options;
  options.refine = false;
  o.table = BuildTable({cube}, options);
  o.voter = std::make_unique<AspectVoter>();
  VoterConfig vc;
  vc.sigma_point_px = vc.sigma_line_px = sigma_px;
  EXPECT_TRUE(o.voter->Init(o.table->view, vc).ok());
  // A general view of the cube: the aspect with the most corners.
  uint32_t best = 0;
  for (uint32_t a = 0; a < o.table->view.aspect_count(); ++a) {
    if (o.table->view.aspect(a).n_corners > o.table->view.aspect(best).n_corners) best = a;
  }
  const AspectRecord& rec = o.table->view.aspect(best);
  EXPECT_TRUE(ComputeAspect(cube,
                            Eigen::Vector3f(rec.dir_model[0], rec.dir_model[1], rec.dir_model[2]),
                            AspectConfig{}, &o.view)
                  .ok());
  o.basis = rec.first_basis;
  const AspectBasis& b = o.table->view.basis(o.basis);
  for (int k = 0; k < o.view.n_corners; ++k) {
    if (o.view.corners[k].corner == b.corners[0]) o.i = k;
    if (o.view.corners[k].corner == b.corners[1]) o.j = k;
  }
  return o;
}

TEST(AspectVoter, PointVotesMeasureImageDistanceAtAnyBasisScale) {
  // Eq. 2.10: moving one scene corner by d pixels lowers its vote to exp(-d^2 / sigma^2),
  // whether the object appears small or large (hash distances are scaled by the basis).
  OneBasis o = MakeOneBasis(4.0f);
  ASSERT_GE(o.i, 0);
  ASSERT_GE(o.j, 0);
  const AspectBasis& b = o.table->view.basis(o.basis);
  ASSERT_GT(b.n_point_entries, 0);
  for (float scale : {500.0f, 1500.0f}) {
    for (float d : {0.0f, 2.0f, 4.0f, 6.0f}) {
      AspectScene s = SceneOfAspect(o.view, scale, 0.3f, {10.0f, 20.0f});
      s.lines.clear();
      int moved = -1;
      for (int k = 0; k < static_cast<int>(s.points.size()) && moved < 0; ++k) {
        if (k != o.i && k != o.j) moved = k;
      }
      s.points[moved].xy += Eigen::Vector2f(0.6f * d, 0.8f * d);
      AspectHypothesis h[1];
      testing::VotePair(*o.voter, s.points, s.lines, o.i, o.j, 0.0f, h, 1);
      const float others = static_cast<float>(b.n_point_entries - 1);
      const float expected = (others + std::exp(-d * d / 16.0f)) / b.n_point_entries;
      EXPECT_NEAR(o.voter->LastVote(o.basis), expected, 2e-3f) << scale << " " << d;
    }
  }
}

TEST(AspectVoter, EachEntryVotesOncePerSceneBasis) {
  OneBasis o = MakeOneBasis(4.0f);
  AspectScene s = SceneOfAspect(o.view, 800.0f, 0.0f, {0.0f, 0.0f});
  // Every corner twice, every line twice: the vote does not change.
  const size_t n_points = s.points.size(), n_lines = s.lines.size();
  for (size_t k = 0; k < n_points; ++k) s.points.push_back(s.points[k]);
  for (size_t k = 0; k < n_lines; ++k) s.lines.push_back(s.lines[k]);
  AspectHypothesis h[1];
  testing::VotePair(*o.voter, s.points, s.lines, o.i, o.j, 0.0f, h, 1);
  EXPECT_NEAR(o.voter->LastVote(o.basis), 2.0f, 0.01f);
}

TEST(AspectVoter, KeyRangeSelectsTheBasesThatMayVote) {
  // Keys are the bases' apparent sizes (as the recogniser sets them): a scene basis whose size
  // range excludes a model basis gives it no vote, a disabled (NaN) basis never gets one.
  OneBasis o = MakeOneBasis(4.0f);
  const AspectScene s = SceneOfAspect(o.view, 800.0f, 0.0f, {0.0f, 0.0f});
  std::vector<float> keys(o.table->view.basis_count());
  for (uint32_t b = 0; b < keys.size(); ++b) {
    const AspectBasis& basis = o.table->view.basis(b);
    keys[b] = AspectApparentSizeMm(o.table->view.aspect(basis.aspect), basis);
  }
  const float size = keys[o.basis];
  o.voter->SetBasisKeys(keys.data());
  VoteScene scene;
  scene.points = s.points.data();
  scene.n_points = static_cast<int>(s.points.size());
  scene.lines = s.lines.data();
  scene.n_lines = static_cast<int>(s.lines.size());
  VoteRequest request;
  request.frame = SimilarityFrame(s.points[o.i].xy, s.points[o.j].xy);
  request.exclude[0] = o.i;
  request.exclude[1] = o.j;
  request.n_exclude = 2;
  AspectHypothesis h[8];
  request.key_lo = 0.95f * size;
  request.key_hi = 1.05f * size;
  o.voter->Vote(scene, request, h, 8);
  EXPECT_NEAR(o.voter->LastVote(o.basis), 2.0f, 0.01f);
  request.key_lo = 1.5f * size;
  request.key_hi = 3.0f * size;
  o.voter->Vote(scene, request, h, 8);
  EXPECT_EQ(o.voter->LastVote(o.basis), 0.0f);
  keys[o.basis] = NAN;
  request.key_lo = -INFINITY;
  request.key_hi = INFINITY;
  o.voter->Vote(scene, request, h, 8);
  EXPECT_EQ(o.voter->LastVote(o.basis), 0.0f);
}

TEST(AspectVoter, RefusesBadSettings) {
  auto voter = std::make_unique<AspectVoter>();
  EXPECT_EQ(voter->Init(AspectTableView{}, VoterConfig{}).code(), StatusCode::kInvalidArgument);
  OneBasis o = MakeOneBasis(4.0f);
  VoterConfig bad;
  bad.sigma_point_px = 0.0f;
  EXPECT_EQ(voter->Init(o.table->view, bad).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace sh
