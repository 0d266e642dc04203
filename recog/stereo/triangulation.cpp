#include "recog/stereo/triangulation.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>

namespace sh {

bool TriangulateMidpoint(const Eigen::Vector3d& origin_a, const Eigen::Vector3d& direction_a,
                         const Eigen::Vector3d& origin_b, const Eigen::Vector3d& direction_b,
                         RayMidpoint* out) {
  // Minimise |origin_a + s a - origin_b - t b|^2 over s, t (a, b unit).
  const Eigen::Vector3d w = origin_a - origin_b;
  const double ab = direction_a.dot(direction_b);
  const double denom = 1.0 - ab * ab;  // sin^2 of the angle between the rays
  if (!(denom > 1e-18)) return false;
  const double wa = direction_a.dot(w);
  const double wb = direction_b.dot(w);
  const double s = (ab * wb - wa) / denom;
  const double t = (wb - ab * wa) / denom;
  const Eigen::Vector3d pa = origin_a + s * direction_a;
  const Eigen::Vector3d pb = origin_b + t * direction_b;
  out->p_mm = 0.5 * (pa + pb);
  out->gap_mm = (pa - pb).norm();
  out->depth_a_mm = s;
  out->depth_b_mm = t;
  return true;
}

bool TriangulatePixels(const StereoCalibration& calib, const Eigen::Vector2d& left_px,
                       const Eigen::Vector2d& right_px, RayMidpoint* out) {
  const Eigen::Vector3d ray_left = PixelRay(calib.left, left_px);
  // The right ray expressed in the left frame: x_left = R^T (x_right - T).
  const Eigen::Vector3d ray_right =
      calib.right_R_left.transpose() * PixelRay(calib.right, right_px);
  return TriangulateMidpoint(Eigen::Vector3d::Zero(), ray_left, RightCentreInLeft(calib), ray_right,
                             out);
}

bool FitLinePlaneNormal(const CameraIntrinsics& cam, const Eigen::Vector2d* pixels, int count,
                        Eigen::Vector3d* normal_cam) {
  if (count < 2) return false;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d r = PixelRay(cam, pixels[i]);
    scatter += r * r.transpose();
  }
  // Eigenvalues ascending; the plane is defined when the two largest are clearly non-zero (the
  // rays span two directions), i.e. the pixels are not all the same point.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  if (eig.info() != Eigen::Success) return false;
  if (!(eig.eigenvalues()(1) > 1e-14 * eig.eigenvalues()(2))) return false;
  *normal_cam = eig.eigenvectors().col(0).normalized();
  return true;
}

bool IntersectPlanes(const Plane3& a, const Plane3& b, double min_sin_angle, Line3* line) {
  const Eigen::Vector3d direction = a.normal.cross(b.normal);
  const double sin_angle = direction.norm();
  if (!(sin_angle >= min_sin_angle) || sin_angle < 1e-12) return false;
  line->direction = direction / sin_angle;
  // The point on both planes closest to the origin also satisfies direction . x = 0.
  Eigen::Matrix3d A;
  A.row(0) = a.normal.transpose();
  A.row(1) = b.normal.transpose();
  A.row(2) = line->direction.transpose();
  line->point_mm = A.inverse() * Eigen::Vector3d(a.d_mm, b.d_mm, 0.0);
  return line->point_mm.allFinite();
}

bool RayLineParameter(const Line3& line, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& direction, double* s_mm) {
  RayMidpoint m;
  // 1e-9 rad between ray and line is hopeless anyway; require about 0.06 degrees so that the
  // parameter is not dominated by noise.
  const double ab = line.direction.dot(direction);
  if (1.0 - ab * ab < 1e-6) return false;
  if (!TriangulateMidpoint(line.point_mm, line.direction, origin, direction, &m)) return false;
  if (!(m.depth_b_mm > 0.0)) return false;
  *s_mm = m.depth_a_mm;
  return true;
}

}  // namespace sh
