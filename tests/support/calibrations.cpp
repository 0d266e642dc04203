#include "tests/support/calibrations.hpp"

#include <Eigen/Geometry>

namespace sh::testing {
namespace {

// Intrinsics around a focal length, principal point near the image centre; distortion terms up
// to the given magnitudes (k3 = 0 draws nothing, so the random stream of a rig without it stays
// as it was).
struct IntrinsicsSpread {
  int width, height;
  double fx, k1, k2, p, k3;
};

void RandomIntrinsics(const IntrinsicsSpread& s, std::mt19937& rng, CameraIntrinsics* cam) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  cam->width = s.width;
  cam->height = s.height;
  cam->fx = s.fx + 100.0 * u(rng);
  cam->fy = cam->fx * (1.0 + 0.01 * u(rng));
  cam->cx = 0.5 * s.width + 20.0 * u(rng);
  cam->cy = 0.5 * s.height + 20.0 * u(rng);
  cam->k1 = s.k1 * u(rng);
  cam->k2 = s.k2 * u(rng);
  cam->p1 = s.p * u(rng);
  cam->p2 = s.p * u(rng);
  cam->k3 = s.k3 != 0.0 ? s.k3 * u(rng) : 0.0;
}

}  // namespace

StereoCalibration TestCalibration() {
  StereoCalibration calib;
  CameraIntrinsics cam;
  cam.width = 756;
  cam.height = 581;
  cam.fx = 800.0;
  cam.fy = 802.0;
  cam.cx = 377.0;
  cam.cy = 291.5;
  cam.k1 = -0.15;
  cam.k2 = 0.05;
  cam.p1 = 0.0005;
  cam.p2 = -0.0003;
  calib.left = cam;
  cam.cx = 380.5;
  cam.k1 = -0.12;
  calib.right = cam;
  const Eigen::Vector3d centre(100.0, 0.0, 0.0);  // right camera centre in the left frame
  const Eigen::Vector3d z = (Eigen::Vector3d(0, 0, 500) - centre).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  calib.right_R_left.row(0) = x.transpose();
  calib.right_R_left.row(1) = y.transpose();
  calib.right_R_left.row(2) = z.transpose();
  calib.right_t_left_mm = -(calib.right_R_left * centre);
  return calib;
}

StereoCalibration RandomRig(std::mt19937& rng, double distortion) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  StereoCalibration c;
  const IntrinsicsSpread spread{
      1280, 1024, 1400.0, distortion * 0.2, distortion * 0.05, distortion * 0.001, 0.0};
  RandomIntrinsics(spread, rng, &c.left);
  RandomIntrinsics(spread, rng, &c.right);
  // Right camera 120 mm to the right, turned inwards by about 8 degrees (about y).
  const double toe_in = (8.0 + 2.0 * u(rng)) * 3.14159265358979 / 180.0;
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(toe_in, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.02 * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()))
          .toRotationMatrix();
  const Eigen::Vector3d right_centre_left(120.0 + 5.0 * u(rng), 3.0 * u(rng), 3.0 * u(rng));
  c.right_R_left = R;
  c.right_t_left_mm = -R * right_centre_left;
  return c;
}

StereoCalibration RandomCalibration(std::mt19937& rng, int width, int height) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  StereoCalibration c;
  // f about 0.94 image widths (1200 px at 1280); distortion a lens of that field of view can
  // have, one to one out to the image corners (stronger negative terms fold the image, which
  // ValidateStereoCalibration refuses).
  const IntrinsicsSpread spread{width, height, 0.9375 * width, 0.1, 0.05, 0.002, 0.01};
  RandomIntrinsics(spread, rng, &c.left);
  RandomIntrinsics(spread, rng, &c.right);
  const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
  c.right_R_left = Eigen::AngleAxisd(0.2 * u(rng), axis).toRotationMatrix();
  c.right_t_left_mm = Eigen::Vector3d(-120.0 + 10.0 * u(rng), 5.0 * u(rng), 5.0 * u(rng));
  return c;
}

}  // namespace sh::testing
