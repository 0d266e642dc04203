// The viewing sphere: grid spacing, refinement views, and the symmetry-reduced part covering
// every view.
#include "recog/mono/view_sphere.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "tests/mono/mono_fixtures.hpp"

namespace sh {
namespace {

float AngleDeg(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return std::acos(std::max(-1.0f, std::min(1.0f, a.normalized().dot(b.normalized())))) *
         57.2957795f;
}

std::vector<ViewDirection> Grid(float spacing) {
  std::vector<ViewDirection> grid(4096);
  const int n = InitialViewGrid(spacing, grid.data(), static_cast<int>(grid.size()));
  EXPECT_LE(n, static_cast<int>(grid.size()));
  grid.resize(n);
  return grid;
}

Eigen::Vector3f RandomDirection(std::mt19937& rng) {
  std::normal_distribution<float> g;
  return Eigen::Vector3f(g(rng), g(rng), g(rng)).normalized();
}

TEST(ViewSphere, GridViewsAreSpreadEvenly) {
  for (float spacing : {15.0f, 10.0f}) {
    const std::vector<ViewDirection> grid = Grid(spacing);
    // Area per view about spacing^2: 4 pi / n within a third of it.
    const float area_deg2 = 4.0f * 3.14159265f * 57.2957795f * 57.2957795f / grid.size();
    EXPECT_NEAR(area_deg2, spacing * spacing, spacing * spacing / 3.0f) << spacing;
    // Every direction has a grid view within the covering radius (about 0.7 spacings).
    std::mt19937 rng(7);
    for (int i = 0; i < 2000; ++i) {
      const Eigen::Vector3f d = RandomDirection(rng);
      float nearest = 180.0f;
      for (const ViewDirection& v : grid) nearest = std::min(nearest, AngleDeg(d, v.dir_model));
      ASSERT_LT(nearest, 0.75f * spacing) << spacing;
    }
    for (const ViewDirection& v : grid) {
      EXPECT_NEAR(v.dir_model.norm(), 1.0f, 1e-5f);
      EXPECT_LT((v.dir_model - ViewVector(v.theta_deg, v.phi_deg)).norm(), 1e-5f);
      EXPECT_EQ(v.level, 0);
    }
  }
}

TEST(ViewSphere, GridRefusesBadSpacingAndReportsOverflow) {
  ViewDirection views[8];
  EXPECT_EQ(InitialViewGrid(0.0f, views, 8), 0);
  EXPECT_EQ(InitialViewGrid(120.0f, views, 8), 0);
  // 15 degrees needs far more than 8 views: the count says so, nothing beyond 8 is written.
  EXPECT_GT(InitialViewGrid(15.0f, views, 8), 8);
}

TEST(ViewSphere, RefinementViewsLieHalfWayDiagonally) {
  for (const ViewDirection& parent : Grid(15.0f)) {
    ViewDirection children[4];
    RefinementViews(parent, children);
    for (const ViewDirection& c : children) {
      EXPECT_EQ(c.level, parent.level + 1);
      EXPECT_FLOAT_EQ(c.spacing_deg, 0.5f * parent.spacing_deg);
      // Half a spacing along each tangent axis: about 0.71 spacings away.
      EXPECT_NEAR(AngleDeg(parent.dir_model, c.dir_model), 0.707f * parent.spacing_deg, 0.6f);
      EXPECT_LT((c.dir_model - ViewVector(c.theta_deg, c.phi_deg)).norm(), 1e-3f);
    }
    // Four distinct views.
    for (int a = 0; a < 4; ++a) {
      for (int b = a + 1; b < 4; ++b) {
        EXPECT_GT(AngleDeg(children[a].dir_model, children[b].dir_model), 3.0f);
      }
    }
  }
}

TEST(ViewSphere, SymmetryDomainHoldsOneImageOfEveryView) {
  for (const char* name : {"cube", "hexagon", "star", "trapezium"}) {
    SCOPED_TRACE(name);
    const Model& m = testing::ReferenceModel(name);
    ASSERT_GT(m.n_symmetries, 1);
    std::mt19937 rng(3);
    int inside = 0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3f d = RandomDirection(rng);
      inside += InSymmetryDomain(m, d, 0.0f);
      bool covered = false;
      for (int k = 0; k < m.n_symmetries && !covered; ++k) {
        covered = InSymmetryDomain(m, m.symmetry(k) * d, 0.0f);
      }
      ASSERT_TRUE(covered);
    }
    // Without margin the part is one of n_symmetries equal parts of the sphere.
    EXPECT_NEAR(static_cast<float>(inside) / n, 1.0f / m.n_symmetries,
                0.25f / m.n_symmetries + 0.01f);
    // With a margin of one spacing, the kept grid views cover every view up to a symmetry.
    const std::vector<ViewDirection> grid = Grid(15.0f);
    std::vector<Eigen::Vector3f> kept;
    for (const ViewDirection& v : grid) {
      if (InSymmetryDomain(m, v.dir_model, 15.0f)) kept.push_back(v.dir_model);
    }
    EXPECT_LT(kept.size(), grid.size());
    for (int i = 0; i < 500; ++i) {
      const Eigen::Vector3f d = RandomDirection(rng);
      float nearest = 180.0f;
      for (int k = 0; k < m.n_symmetries; ++k) {
        for (const Eigen::Vector3f& v : kept) {
          nearest = std::min(nearest, AngleDeg(m.symmetry(k) * d, v));
        }
      }
      ASSERT_LT(nearest, 0.75f * 15.0f);
    }
  }
}

}  // namespace
}  // namespace sh
