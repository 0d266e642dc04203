// The convex hull of 2-D points (Andrew's monotone chain), for silhouettes in images and
// footprints on the table. No allocation: the caller's arrays.
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace sh {

// z of (a - o) x (b - o): > 0 for a left turn o -> a -> b.
inline float Cross2D(const Eigen::Vector2f& o, const Eigen::Vector2f& a, const Eigen::Vector2f& b) {
  return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
}

// Writes the hull of points[0..n) to `hull` in left-turn order (counter-clockwise with y up,
// clockwise on a y-down image), without collinear points, and returns its vertex count (n for
// n < 3 distinct points at most). Sorts `points` in place; `hull` must hold n + 1 points.
inline int ConvexHull2D(Eigen::Vector2f* points, int n, Eigen::Vector2f* hull) {
  std::sort(points, points + n, [](const Eigen::Vector2f& a, const Eigen::Vector2f& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  int k = 0;
  for (int i = 0; i < n; ++i) {
    while (k >= 2 && Cross2D(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (int i = n - 2, lower = k + 1; i >= 0; --i) {
    while (k >= lower && Cross2D(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  return std::max(k - 1, 0);  // the last point repeats the first
}

}  // namespace sh
