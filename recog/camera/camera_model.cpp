#include "recog/camera/camera_model.hpp"

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
  // Fixed-point iteration x = (x_d - tangential(x)) / radial(x); 20 rounds reach 1e-9 px for
  // |k1| < 0.5 within the image, and cost nothing next to feature detection.
  for (int i = 0; i < 20; ++i) {
    const double x = xy.x(), y = xy.y();
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (cam.k1 + r2 * (cam.k2 + r2 * cam.k3));
    const double dx = 2.0 * cam.p1 * x * y + cam.p2 * (r2 + 2.0 * x * x);
    const double dy = cam.p1 * (r2 + 2.0 * y * y) + 2.0 * cam.p2 * x * y;
    xy = {(distorted.x() - dx) / radial, (distorted.y() - dy) / radial};
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
