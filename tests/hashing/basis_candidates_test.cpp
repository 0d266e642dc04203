#include "recog/hashing/basis_candidates.hpp"

#include <gtest/gtest.h>

#include <memory>

namespace sh {
namespace {

// A square outline (four corners, four edges) of side `side_mm` in the plane z = z_mm.
void AddSquare(Scene& scene, const Eigen::Vector3f& corner_mm, float side_mm) {
  const Eigen::Vector3f c[4] = {corner_mm, corner_mm + Eigen::Vector3f(side_mm, 0, 0),
                                corner_mm + Eigen::Vector3f(side_mm, side_mm, 0),
                                corner_mm + Eigen::Vector3f(0, side_mm, 0)};
  for (int k = 0; k < 4; ++k) {
    ASSERT_TRUE(scene.points.push_back(ScenePoint{c[k], {}, 1.0f}));
    ASSERT_TRUE(scene.lines.push_back(SceneLine{c[k], c[(k + 1) % 4], {}, side_mm}));
  }
}

// The scene state BasisCandidates reads, owned here.
struct SceneFixture {
  Scene scene;
  uint8_t point_active[kMaxScenePoints];
  uint8_t line_active[kMaxSceneLines];
  Eigen::Vector3f line_dir[kMaxSceneLines];
  Eigen::Vector3f positions[kMaxScenePoints];
  Eigen::Vector3f topology_scratch[2 * kMaxSceneLines];
  SceneGrid grid;
  SceneTopology topology;
  SceneState state;

  void Prepare() {
    const int np = int(scene.points.size()), nl = int(scene.lines.size());
    for (int i = 0; i < np; ++i) {
      point_active[i] = 1;
      positions[i] = scene.points[i].p_mm;
    }
    for (int i = 0; i < nl; ++i) {
      line_active[i] = 1;
      line_dir[i] = scene.lines[i].direction();
    }
    grid.Build(positions, np, 5.0f);
    state = {&scene, point_active, line_active, line_dir, &grid};
    topology.Build(state, 2.5f, 12.0f, topology_scratch);
  }
};

// `busy` squares stacked in one region (one 50 mm cell) and one slightly smaller square far away.
std::unique_ptr<SceneFixture> BusyAndQuietScene(int busy) {
  auto f = std::make_unique<SceneFixture>();
  for (int k = 0; k < busy; ++k) AddSquare(f->scene, {0.0f, 0.0f, 500.0f + 4.0f * float(k)}, 40.0f);
  AddSquare(f->scene, {300.0f, 0.0f, 500.0f}, 36.0f);
  f->Prepare();
  return f;
}

std::unique_ptr<BasisCandidates> Ordered(const SceneFixture& f,
                                         const BasisCandidates::Policy& policy) {
  auto c = std::make_unique<BasisCandidates>();
  c->Generate(f.state, f.topology, HashFunction::kLinePointMidway, BasisLimits{}, policy);
  return c;
}

// Rank of the first basis whose point lies beyond x_mm (the quiet square), or -1.
int FirstRankBeyond(const BasisCandidates& c, const Scene& scene, float x_mm) {
  for (uint32_t i = 0; i < c.count(); ++i) {
    if (scene.points[c[i].f[1]].p_mm.x() > x_mm) return int(i);
  }
  return -1;
}

// In pure quality order every basis of the busy region comes first; spread over cells, the
// quiet square's best basis comes among the first, and the best basis of all stays first.
TEST(BasisCandidates, CellSpreadBringsAQuietRegionForward) {
  const auto f = BusyAndQuietScene(10);
  BasisCandidates::Policy spread_policy;
  spread_policy.cell_rank_penalty = 1.0f;
  const auto quality = Ordered(*f, {});
  const auto spread = Ordered(*f, spread_policy);
  ASSERT_GT(quality->count(), 100u);
  ASSERT_EQ(spread->count(), quality->count());  // reordered, none dropped
  const int quiet_quality = FirstRankBeyond(*quality, f->scene, 200.0f);
  const int quiet_spread = FirstRankBeyond(*spread, f->scene, 200.0f);
  ASSERT_GE(quiet_quality, 0);
  EXPECT_GE(quiet_quality, 10 * 8);  // behind the eight own bases of each busy square
  EXPECT_GE(quiet_spread, 0);
  EXPECT_LT(quiet_spread, 10);
  for (int k = 0; k < 3; ++k) EXPECT_EQ((*spread)[0].f[k], (*quality)[0].f[k]);
}

// Cells are told apart by their coordinates, not by a hash slot: cell (8, 24, 10) shares a slot
// of a plain 1024-slot hash with the busy cell (0, 0, 10), yet its quiet square is not penalised
// for the busy one's bases.
TEST(BasisCandidates, CellsThatShareAHashSlotAreCountedApart) {
  auto f = std::make_unique<SceneFixture>();
  for (int k = 0; k < 10; ++k) AddSquare(f->scene, {0.0f, 0.0f, 500.0f + 4.0f * float(k)}, 40.0f);
  AddSquare(f->scene, {405.0f, 1205.0f, 500.0f}, 36.0f);
  f->Prepare();
  BasisCandidates::Policy spread_policy;
  spread_policy.cell_rank_penalty = 1.0f;
  const auto spread = Ordered(*f, spread_policy);
  const int quiet = FirstRankBeyond(*spread, f->scene, 200.0f);
  ASSERT_GE(quiet, 0);
  EXPECT_LT(quiet, 10);
}

// Without a penalty the order is the quality order, whatever the cell size.
TEST(BasisCandidates, NoPenaltyKeepsTheQualityOrder) {
  const auto f = BusyAndQuietScene(3);
  BasisCandidates::Policy small_cells;
  small_cells.cell_size_mm = 7.0f;
  const auto a = Ordered(*f, {}), b = Ordered(*f, small_cells);
  ASSERT_TRUE(a->count() > 0 && a->count() == b->count());
  for (uint32_t i = 0; i < a->count(); ++i) {
    for (int k = 0; k < 3; ++k) ASSERT_EQ((*a)[i].f[k], (*b)[i].f[k]) << i;
  }
}

}  // namespace
}  // namespace sh
