#include "recog/hashing/scene_grid.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

namespace sh {
namespace {

std::vector<int> Near(const SceneGrid& grid, const Eigen::Vector3f& p, float r, bool scan) {
  std::vector<int> items;
  auto add = [&items](int j) { items.push_back(j); };
  if (scan) {
    grid.ForEachNearByScan(p, r, add);
  } else {
    grid.ForEachNear(p, r, add);
  }
  return items;
}

// The scan must call back with the same items in the same order: the order of the votes
// decides ties between model bases.
TEST(SceneGrid, ScanVisitsTheSameItemsInTheSameOrder) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> coord(-150.0f, 150.0f);
  auto grid = std::make_unique<SceneGrid>();
  int found = 0;
  for (int n : {1, 40, 500, 3000}) {
    std::vector<Eigen::Vector3f> positions(n);
    for (Eigen::Vector3f& p : positions) p = {coord(rng), coord(rng), 0.3f * coord(rng)};
    // A few on one spot, so that cells hold several items.
    for (int i = 1; i < n && i < 6; ++i) positions[i] = positions[0];
    grid->Build(positions.data(), n, 5.0f);
    for (int q = 0; q < 200; ++q) {
      const Eigen::Vector3f p(coord(rng), coord(rng), coord(rng));
      for (float r : {0.0f, 3.0f, 40.0f, 120.0f, 500.0f}) {
        const std::vector<int> a = Near(*grid, p, r, false), b = Near(*grid, p, r, true);
        ASSERT_EQ(a, b) << n << " items, radius " << r;
        found += int(a.size());
      }
    }
    const std::vector<int> at_item = Near(*grid, positions[0], 0.0f, true);
    EXPECT_GE(at_item.size(), std::min<size_t>(size_t(n), 6));
  }
  EXPECT_GT(found, 0);
}

}  // namespace
}  // namespace sh
