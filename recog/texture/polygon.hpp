// Point-in-polygon with distance, for face contours in image or face coordinates.
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace sh::texture {

// Signed distance of p to the boundary of a simple polygon (either orientation): positive
// inside (crossing-number test), then the distance to the nearest edge.
inline float InsideDistance(const Eigen::Vector2f* poly, int n, const Eigen::Vector2f& p) {
  bool inside = false;
  float best = 1e30f;
  for (int i = 0, j = n - 1; i < n; j = i++) {
    const Eigen::Vector2f& a = poly[j];
    const Eigen::Vector2f& b = poly[i];
    if ((b.y() > p.y()) != (a.y() > p.y()) &&
        p.x() < (a.x() - b.x()) * (p.y() - b.y()) / (a.y() - b.y()) + b.x())
      inside = !inside;
    const Eigen::Vector2f ab = b - a;
    const float t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12f), 0.0f, 1.0f);
    best = std::min(best, (a + t * ab - p).norm());
  }
  return inside ? best : -best;
}

}  // namespace sh::texture
