#include "recog/camera/camera_model.hpp"

#include <Eigen/LU>
#include <cmath>

namespace sh {

Eigen::Vector2d Distort(const CameraIntrinsics& cam, const Eigen::Vector2d& xy) {
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (cam.k1 + r2 * (cam.k2 + r2 * cam.k3));
  const double xd = x * radial + 2.0 * cam.p1 * x * y + cam.p2 * (r2 + 2.0 * x * x);
  const double yd = y * radial + cam.p1 * (r2 + 2.0 * y * y) + 2.0 * cam.p2 * x * y;
  return {xd, yd};
}

bool ProjectToPixel(const CameraIntrinsics& cam, const Eigen::Vector3d& x_cam_mm,
                    Eigen::Vector2d* pixel) {
  if (!(x_cam_mm.z() > 1e-9)) return false;
  const Eigen::Vector2d d = Distort(cam, x_cam_mm.head<2>() / x_cam_mm.z());
  *pixel = {cam.fx * d.x() + cam.cx, cam.fy * d.y() + cam.cy};
  return true;
}

Eigen::Vector2d UndistortPixel(const CameraIntrinsics& cam, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d distorted((pixel.x() - cam.cx) / cam.fx, (pixel.y() - cam.cy) / cam.fy);
  Eigen::Vector2d xy = distorted;
  // A few rounds of OpenCV's fixed-point iteration x = (x_d - tangential(x)) / radial(x) give a
  // start point; on their own they converge slowly (or oscillate) near the image corners of
  // strongly distorted lenses, so Newton's method on Distort(x) = x_d finishes the job.
  for (int i = 0; i < 5; ++i) {
    const double x = xy.x(), y = xy.y();
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (cam.k1 + r2 * (cam.k2 + r2 * cam.k3));
    if (!(radial > 0.1)) break;  // outside the lens' invertible range: leave it to Newton
    const double dx = 2.0 * cam.p1 * x * y + cam.p2 * (r2 + 2.0 * x * x);
    const double dy = cam.p1 * (r2 + 2.0 * y * y) + 2.0 * cam.p2 * x * y;
    xy = {(distorted.x() - dx) / radial, (distorted.y() - dy) / radial};
  }
  Eigen::Vector2d residual = Distort(cam, xy) - distorted;
  // 1e-15 in normalised units is 1e-12 px at any focal length: converged.
  for (int i = 0; i < 20 && residual.squaredNorm() > 1e-30; ++i) {
    const double x = xy.x(), y = xy.y();
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (cam.k1 + r2 * (cam.k2 + r2 * cam.k3));
    const double dradial_dr2 = cam.k1 + r2 * (2.0 * cam.k2 + 3.0 * r2 * cam.k3);
    Eigen::Matrix2d J;
    J(0, 0) = radial + 2.0 * x * x * dradial_dr2 + 2.0 * cam.p1 * y + 6.0 * cam.p2 * x;
    J(0, 1) = 2.0 * x * y * dradial_dr2 + 2.0 * cam.p1 * x + 2.0 * cam.p2 * y;
    J(1, 0) = J(0, 1);
    J(1, 1) = radial + 2.0 * y * y * dradial_dr2 + 6.0 * cam.p1 * y + 2.0 * cam.p2 * x;
    const double det = J.determinant();
    if (!(std::fabs(det) > 1e-12)) break;  // fold of the distortion: no unique inverse
    const Eigen::Vector2d step = J.inverse() * residual;
    // Damped: halve the step until the residual shrinks, so that Newton cannot run away.
    double scale = 1.0;
    for (int k = 0; k < 10; ++k, scale *= 0.5) {
      const Eigen::Vector2d candidate = xy - scale * step;
      const Eigen::Vector2d r = Distort(cam, candidate) - distorted;
      if (r.squaredNorm() < residual.squaredNorm()) {
        xy = candidate;
        residual = r;
        break;
      }
    }
    if (scale < 1e-3) break;
  }
  return xy;
}

Eigen::Vector3d PixelRay(const CameraIntrinsics& cam, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d xy = UndistortPixel(cam, pixel);
  return Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
}

Eigen::Vector3d RightCentreInLeft(const StereoCalibration& calib) {
  // x_right = R x_left + T, so the right centre (x_right = 0) is at x_left = -R^T T.
  return -(calib.right_R_left.transpose() * calib.right_t_left_mm);
}

}  // namespace sh
