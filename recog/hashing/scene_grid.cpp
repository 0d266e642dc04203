#include "recog/hashing/scene_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace sh {

void SceneGrid::Build(const Eigen::Vector3f* positions, int n, float cell_mm) {
  count_ = std::min(n, kMaxItems);
  if (count_ == 0) return;
  Eigen::Vector3f lo = positions[0], hi = positions[0];
  for (int i = 1; i < count_; ++i) {
    lo = lo.cwiseMin(positions[i]);
    hi = hi.cwiseMax(positions[i]);
  }
  // Grow the cell until the box fits in the cell budget.
  float cell = std::max(cell_mm, 1e-3f);
  for (;;) {
    for (int i = 0; i < 3; ++i) dims_[i] = int((hi[i] - lo[i]) / cell) + 1;
    if (int64_t{dims_[0]} * dims_[1] * dims_[2] <= kMaxGridCells) break;
    cell *= 1.5f;
  }
  for (int i = 0; i < 3; ++i) min_[i] = lo[i];
  inv_cell_ = 1.0f / cell;
  std::fill(head_, head_ + ptrdiff_t{dims_[0]} * dims_[1] * dims_[2], int16_t{-1});
  for (int i = 0; i < count_; ++i) {
    positions_[i] = positions[i];
    const int c =
        (CellCoord(positions[i].z(), 2) * dims_[1] + CellCoord(positions[i].y(), 1)) * dims_[0] +
        CellCoord(positions[i].x(), 0);
    next_[i] = head_[c];
    head_[c] = int16_t(i);
  }
  int k = 0;
  for (int z = 0; z < dims_[2]; ++z) {
    for (int y = 0; y < dims_[1]; ++y) {
      for (int x = 0; x < dims_[0]; ++x) {
        for (int16_t it = head_[(z * dims_[1] + y) * dims_[0] + x]; it >= 0; it = next_[it]) {
          order_[k++] = {it, uint16_t(x), uint16_t(y), uint16_t(z)};
        }
      }
    }
  }
}

}  // namespace sh
