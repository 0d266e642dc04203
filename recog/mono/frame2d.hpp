// 2-D basis frames of the aspect hashing (thesis 2.1.2, 6.2) and the vote distances measured in
// the image's metric (thesis eqs. 2.10 and 6.1).
//
// A frame maps hash coordinates h to image coordinates x = origin + axes h. Similarity frames
// (two corners p0, p1) put the origin at their midpoint and the first axis from p0 to p1, the
// second axis perpendicular to it with the same length; affine frames (three corners) put the
// origin at the centroid and the axes along p1 - p0 and p2 - p0. Distances between hash
// coordinates are converted back to image units with the metric G = axes^T axes, so that a vote
// width in pixels means the same for every basis.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>

namespace sh {

struct Frame2d {
  Eigen::Vector2f origin{0, 0};
  Eigen::Matrix2f axes = Eigen::Matrix2f::Identity();  // columns: images of the hash unit axes

  Eigen::Vector2f ToImage(const Eigen::Vector2f& h) const { return origin + axes * h; }
  // The metric of hash space in image units squared: |x1 - x2|^2 = dh^T G dh.
  Eigen::Matrix2f Metric() const { return axes.transpose() * axes; }
};

inline Frame2d SimilarityFrame(const Eigen::Vector2f& p0, const Eigen::Vector2f& p1) {
  const Eigen::Vector2f d = p1 - p0;
  Frame2d f;
  f.origin = 0.5f * (p0 + p1);
  f.axes.col(0) = d;
  f.axes.col(1) = Eigen::Vector2f(-d.y(), d.x());
  return f;
}

inline Frame2d AffineFrame(const Eigen::Vector2f& p0, const Eigen::Vector2f& p1,
                           const Eigen::Vector2f& p2) {
  Frame2d f;
  f.origin = (p0 + p1 + p2) / 3.0f;
  f.axes.col(0) = p1 - p0;
  f.axes.col(1) = p2 - p0;
  return f;
}

// Hash coordinates of image points for a frame, with its inverse precomputed.
struct FrameInverse {
  Eigen::Vector2f origin{0, 0};
  Eigen::Matrix2f inv = Eigen::Matrix2f::Identity();
  Eigen::Matrix2f metric = Eigen::Matrix2f::Identity();
  // Smallest image length of a unit hash vector: a hash distance r is at least r * min_scale
  // pixels, so a vote reach of R pixels is at most R / min_scale in hash units.
  float min_scale = 1.0f;

  explicit FrameInverse(const Frame2d& f) : origin(f.origin), metric(f.Metric()) {
    inv = f.axes.inverse();
    // Smallest eigenvalue of the symmetric 2 x 2 metric.
    const float a = metric(0, 0), b = metric(0, 1), c = metric(1, 1);
    const float mean = 0.5f * (a + c);
    const float diff = std::sqrt(0.25f * (a - c) * (a - c) + b * b);
    min_scale = std::sqrt(std::max(0.0f, mean - diff));
  }
  Eigen::Vector2f ToHash(const Eigen::Vector2f& x) const { return inv * (x - origin); }
  Eigen::Vector2f DirectionToHash(const Eigen::Vector2f& v) const { return inv * v; }
};

// Squared image distance of two points given in hash coordinates (eq. 2.10).
inline float PointDistance2(const Eigen::Matrix2f& G, const Eigen::Vector2f& dh) {
  return dh.dot(G * dh);
}

// A scene line prepared for the vote in one frame: a point and a direction in hash
// coordinates, with G applied once.
struct HashLine {
  Eigen::Vector2f s{0, 0};   // a point of the line
  Eigen::Vector2f v{1, 0};   // its direction (any length)
  Eigen::Vector2f Gv{1, 0};  // G v
  float vGv = 1;             // |v|_G^2
  float inv_vGv = 1;
};

inline HashLine MakeHashLine(const Eigen::Matrix2f& G, const Eigen::Vector2f& s_hash,
                             const Eigen::Vector2f& v_hash) {
  HashLine l;
  l.s = s_hash;
  l.v = v_hash;
  l.Gv = G * v_hash;
  l.vGv = v_hash.dot(l.Gv);
  l.inv_vGv = 1.0f / l.vGv;
  return l;
}

// Squared image distance between a model segment (centre c, unit hash direction u, hash length
// len) and a scene line, averaged over the segment (eq. 6.1: the point-line distance of eq. 4.4
// with inner products and norms taken in the image metric G):
//   |c - s|_G^2 - (v . G (c - s))^2 / |v|_G^2 + len^2 / 12 (|u|_G^2 - (v . G u)^2 / |v|_G^2)
// Both terms are evaluated as G-norms of the components G-perpendicular to v, which is the same
// value without the cancellation of the difference form (it can go negative in float).
inline float SegmentLineDistance2(const Eigen::Matrix2f& G, const HashLine& line,
                                  const Eigen::Vector2f& c, const Eigen::Vector2f& u, float len) {
  const Eigen::Vector2f w = c - line.s;
  const Eigen::Vector2f w_perp = w - (line.Gv.dot(w) * line.inv_vGv) * line.v;
  const Eigen::Vector2f u_perp = u - (line.Gv.dot(u) * line.inv_vGv) * line.v;
  return w_perp.dot(G * w_perp) + len * len * (1.0f / 12.0f) * u_perp.dot(G * u_perp);
}

}  // namespace sh
