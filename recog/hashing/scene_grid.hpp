// A uniform grid over 3-D points for fixed-radius neighbour queries, statically sized.
//
// Built once per scene (points, or line end points) and queried by basis ordering and pose
// refinement. The cell size grows automatically when the scene's bounding box would need more
// than kMaxGridCells cells, so any scene fits; queries stay correct, only slower.
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace sh {

class SceneGrid {
 public:
  static constexpr int kMaxItems = 4096;
  static constexpr int kMaxGridCells = 65536;

  // Items beyond kMaxItems are ignored (count() tells how many were kept).
  void Build(const Eigen::Vector3f* positions, int n, float cell_mm);

  // Calls fn(item) for each item within radius_mm of p (exact distance test).
  template <typename Fn>
  void ForEachNear(const Eigen::Vector3f& p, float radius_mm, Fn&& fn) const {
    if (count_ == 0) return;
    int lo[3], hi[3];
    QueryBox(p, radius_mm, lo, hi);
    const float r2 = radius_mm * radius_mm;
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int x = lo[0]; x <= hi[0]; ++x) {
          for (int16_t it = head_[(z * dims_[1] + y) * dims_[0] + x]; it >= 0; it = next_[it]) {
            if ((positions_[it] - p).squaredNorm() <= r2) fn(int(it));
          }
        }
      }
    }
  }
  // The same calls as ForEachNear, in the same order, by one pass over the items in cell order
  // instead of over the cells of the query's box: cheaper when the box holds many cells (the
  // neighbourhood of a scene basis covers most of the scene).
  template <typename Fn>
  void ForEachNearByScan(const Eigen::Vector3f& p, float radius_mm, Fn&& fn) const {
    if (count_ == 0) return;
    int lo[3], hi[3];
    QueryBox(p, radius_mm, lo, hi);
    const float r2 = radius_mm * radius_mm;
    for (int k = 0; k < count_; ++k) {
      const ItemCell& c = order_[k];
      if (c.x < lo[0] || c.x > hi[0] || c.y < lo[1] || c.y > hi[1] || c.z < lo[2] || c.z > hi[2])
        continue;
      if ((positions_[c.item] - p).squaredNorm() <= r2) fn(int(c.item));
    }
  }
  int count() const { return count_; }

 private:
  // Cells [lo, hi] per axis that hold every point within radius_mm of p.
  void QueryBox(const Eigen::Vector3f& p, float radius_mm, int* lo, int* hi) const {
    for (int i = 0; i < 3; ++i) {
      lo[i] = CellCoord(p[i] - radius_mm, i);
      hi[i] = CellCoord(p[i] + radius_mm, i);
    }
  }
  int CellCoord(float v, int axis) const {
    const int c = int((v - min_[axis]) * inv_cell_);
    return c < 0 ? 0 : (c >= dims_[axis] ? dims_[axis] - 1 : c);
  }

  struct ItemCell {
    int16_t item;
    uint16_t x, y, z;  // cell coordinates
  };

  Eigen::Vector3f positions_[kMaxItems];
  ItemCell order_[kMaxItems];  // items in the order ForEachNear visits them: by cell, then list
  int16_t next_[kMaxItems];
  int16_t head_[kMaxGridCells];
  float min_[3] = {0, 0, 0};
  float inv_cell_ = 1.0f;
  int dims_[3] = {1, 1, 1};
  int count_ = 0;
};

}  // namespace sh
