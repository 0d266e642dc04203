// Midpoint triangulation against OpenCV's linear (DLT) triangulation on distorted rigs.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "recog/stereo/triangulation.hpp"
#include "tests/support/stereo_scene.hpp"

namespace sh {
namespace {

cv::Mat K(const CameraIntrinsics& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}
cv::Mat D(const CameraIntrinsics& c) {
  return (cv::Mat_<double>(1, 5) << c.k1, c.k2, c.p1, c.p2, c.k3);
}

// OpenCV's pipeline: undistortPoints to normalised coordinates, then triangulatePoints with
// P_left = [I | 0], P_right = [R | T].
std::vector<Eigen::Vector3d> OpenCvTriangulate(const StereoCalibration& calib,
                                               const std::vector<cv::Point2d>& left_px,
                                               const std::vector<cv::Point2d>& right_px) {
  std::vector<cv::Point2d> left_norm, right_norm;
  const cv::TermCriteria converge(cv::TermCriteria::COUNT, 100, 0);
  cv::undistortPoints(left_px, left_norm, K(calib.left), D(calib.left), cv::noArray(),
                      cv::noArray(), converge);
  cv::undistortPoints(right_px, right_norm, K(calib.right), D(calib.right), cv::noArray(),
                      cv::noArray(), converge);
  cv::Mat P_left = cv::Mat::eye(3, 4, CV_64F), P_right(3, 4, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) P_right.at<double>(r, c) = calib.right_R_left(r, c);
    P_right.at<double>(r, 3) = calib.right_t_left_mm(r);
  }
  cv::Mat homogeneous;
  cv::triangulatePoints(P_left, P_right, left_norm, right_norm, homogeneous);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < homogeneous.cols; ++i) {
    const double w = homogeneous.at<double>(3, i);
    out.emplace_back(homogeneous.at<double>(0, i) / w, homogeneous.at<double>(1, i) / w,
                     homogeneous.at<double>(2, i) / w);
  }
  return out;
}

TEST(TriangulationOpenCv, AgreesWithTriangulatePoints) {
  std::mt19937 rng(40);
  std::normal_distribution<double> noise(0.0, 0.3);
  double worst_exact_mm = 0.0, worst_noisy_diff_mm = 0.0, ours_rms = 0.0, opencv_rms = 0.0;
  int n = 0;
  for (int rig = 0; rig < 10; ++rig) {
    // Moderate distortion, where OpenCV's undistortion converges everywhere.
    const StereoCalibration calib = testing::RandomRig(rng, 0.5);
    std::vector<Eigen::Vector3d> truth;
    std::vector<cv::Point2d> left, right, left_noisy, right_noisy;
    while (truth.size() < 100) {
      const Eigen::Vector3d p = testing::RandomScenePoint(rng);
      Eigen::Vector2d l, r;
      if (!testing::ProjectBoth(calib, p, &l, &r)) continue;
      truth.push_back(p);
      left.emplace_back(l.x(), l.y());
      right.emplace_back(r.x(), r.y());
      left_noisy.emplace_back(l.x() + noise(rng), l.y() + noise(rng));
      right_noisy.emplace_back(r.x() + noise(rng), r.y() + noise(rng));
    }
    const std::vector<Eigen::Vector3d> exact = OpenCvTriangulate(calib, left, right);
    const std::vector<Eigen::Vector3d> noisy = OpenCvTriangulate(calib, left_noisy, right_noisy);
    for (size_t i = 0; i < truth.size(); ++i) {
      RayMidpoint m;
      ASSERT_TRUE(TriangulatePixels(calib, {left[i].x, left[i].y}, {right[i].x, right[i].y}, &m));
      worst_exact_mm = std::max(worst_exact_mm, (m.p_mm - exact[i]).norm());
      ASSERT_TRUE(TriangulatePixels(calib, {left_noisy[i].x, left_noisy[i].y},
                                    {right_noisy[i].x, right_noisy[i].y}, &m));
      worst_noisy_diff_mm = std::max(worst_noisy_diff_mm, (m.p_mm - noisy[i]).norm());
      ours_rms += (m.p_mm - truth[i]).squaredNorm();
      opencv_rms += (noisy[i] - truth[i]).squaredNorm();
      ++n;
    }
  }
  ours_rms = std::sqrt(ours_rms / n);
  opencv_rms = std::sqrt(opencv_rms / n);
  RecordProperty("worst_exact_mm", std::to_string(worst_exact_mm));
  RecordProperty("noisy_rms_ours_mm", std::to_string(ours_rms));
  RecordProperty("noisy_rms_opencv_mm", std::to_string(opencv_rms));
  std::printf(
      "noise-free max |ours - OpenCV| %.2e mm; 0.3 px noise: RMS error ours %.3f mm, "
      "OpenCV %.3f mm, max |ours - OpenCV| %.3f mm\n",
      worst_exact_mm, ours_rms, opencv_rms, worst_noisy_diff_mm);
  EXPECT_LT(worst_exact_mm, 1e-6);
  // Two different estimators on noisy data: neither is much worse than the other.
  EXPECT_LT(ours_rms, 1.2 * opencv_rms);
  EXPECT_LT(opencv_rms, 1.2 * ours_rms);
}

}  // namespace
}  // namespace sh
