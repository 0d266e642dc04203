// Projection and undistortion against OpenCV on random points and random distortion.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "recog/camera/camera_model.hpp"

namespace sh {
namespace {

CameraIntrinsics RandomCamera(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  CameraIntrinsics c;
  c.width = 1280;
  c.height = 1024;
  c.fx = 1000.0 + 300.0 * u(rng);
  c.fy = c.fx * (1.0 + 0.02 * u(rng));
  c.cx = 640.0 + 30.0 * u(rng);
  c.cy = 512.0 + 30.0 * u(rng);
  c.k1 = 0.3 * u(rng);
  c.k2 = 0.1 * u(rng);
  c.p1 = 0.003 * u(rng);
  c.p2 = 0.003 * u(rng);
  c.k3 = 0.05 * u(rng);
  return c;
}

// True when the radial distortion r -> r * radial(r) keeps increasing until it covers the image
// corners, i.e. every pixel has exactly one undistorted direction (a real lens; random
// coefficients can fold the image over).
bool IsInvertible(const CameraIntrinsics& c) {
  const double corner_px =
      std::hypot(std::max(c.cx, c.width - c.cx), std::max(c.cy, c.height - c.cy));
  const double corner_norm = corner_px / std::min(c.fx, c.fy);  // distorted radius to cover
  double previous = 0.0;
  for (double r = 0.01; r < 10.0; r += 0.01) {
    const double r2 = r * r;
    const double rd = r * (1.0 + r2 * (c.k1 + r2 * (c.k2 + r2 * c.k3)));
    if (rd <= previous) return false;  // folds inside the image
    if (rd > 1.2 * corner_norm) return true;
    previous = rd;
  }
  return false;
}

cv::Mat K(const CameraIntrinsics& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}
cv::Mat D(const CameraIntrinsics& c) {
  return (cv::Mat_<double>(1, 5) << c.k1, c.k2, c.p1, c.p2, c.k3);
}

TEST(CameraModelOpenCv, ProjectionMatchesProjectPoints) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst_px = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    const CameraIntrinsics cam = RandomCamera(rng);
    std::vector<cv::Point3d> points;
    for (int i = 0; i < 100; ++i) {
      const double z = 300.0 + 1500.0 * (u(rng) + 1.0);
      points.emplace_back(0.45 * z * u(rng), 0.35 * z * u(rng), z);  // within about 50 x 40 deg
    }
    std::vector<cv::Point2d> expected;
    cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K(cam), D(cam), expected);
    for (size_t i = 0; i < points.size(); ++i) {
      Eigen::Vector2d pixel;
      ASSERT_TRUE(
          ProjectToPixel(cam, Eigen::Vector3d(points[i].x, points[i].y, points[i].z), &pixel));
      worst_px = std::max(worst_px, (pixel - Eigen::Vector2d(expected[i].x, expected[i].y)).norm());
    }
  }
  RecordProperty("worst_px", std::to_string(worst_px));
  EXPECT_LT(worst_px, 1e-8);
}

TEST(CameraModelOpenCv, UndistortionMatchesUndistortPoints) {
  std::mt19937 rng(32);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int compared = 0;
  for (int trial = 0; trial < 20; ++trial) {
    CameraIntrinsics cam = RandomCamera(rng);
    while (!IsInvertible(cam)) cam = RandomCamera(rng);
    std::vector<cv::Point2d> pixels;
    for (int i = 0; i < 100; ++i) pixels.emplace_back(cam.width * u(rng), cam.height * u(rng));
    std::vector<cv::Point2d> expected;
    // OpenCV's own iteration count is 5 by default; ask for a converged answer.
    cv::undistortPoints(pixels, expected, K(cam), D(cam), cv::noArray(), cv::noArray(),
                        cv::TermCriteria(cv::TermCriteria::COUNT, 100, 0));
    for (size_t i = 0; i < pixels.size(); ++i) {
      const Eigen::Vector2d pixel(pixels[i].x, pixels[i].y);
      const Eigen::Vector2d xy = UndistortPixel(cam, pixel);
      Eigen::Vector2d back;
      ASSERT_TRUE(ProjectToPixel(cam, Eigen::Vector3d(xy.x(), xy.y(), 1.0), &back));
      EXPECT_LT((back - pixel).norm(), 1e-9) << "trial " << trial << " pixel " << pixels[i];
      // OpenCV's fixed-point iteration does not converge everywhere for strong distortion; where
      // it did (its answer re-projects onto the pixel), both must agree.
      Eigen::Vector2d opencv_back;
      ASSERT_TRUE(
          ProjectToPixel(cam, Eigen::Vector3d(expected[i].x, expected[i].y, 1.0), &opencv_back));
      if ((opencv_back - pixel).norm() < 1e-9) {
        ++compared;
        EXPECT_LT((xy - Eigen::Vector2d(expected[i].x, expected[i].y)).norm() * cam.fx, 1e-8);
      }
    }
  }
  RecordProperty("compared_with_opencv", compared);
  EXPECT_GT(compared, 1000);  // most of the 2000 pixels
}

}  // namespace
}  // namespace sh
