// The calibration file format against OpenCV's own FileStorage, in both directions.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <random>
#include <string>

#include "recog/camera/calibration_yaml.hpp"
#include "tests/support/calibrations.hpp"

namespace sh {
namespace {

using testing::RandomCalibration;

cv::Mat CameraMatrix(const CameraIntrinsics& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}
cv::Mat Distortion(const CameraIntrinsics& c) {
  return (cv::Mat_<double>(1, 5) << c.k1, c.k2, c.p1, c.p2, c.k3);
}

double MaxAbsDiff(const cv::Mat& a, const cv::Mat& b) {
  EXPECT_EQ(a.total(), b.total());
  cv::Mat a64, b64;
  a.convertTo(a64, CV_64F);
  b.convertTo(b64, CV_64F);
  return cv::norm(a64.reshape(1, 1), b64.reshape(1, 1), cv::NORM_INF);
}

TEST(CalibrationYamlOpenCv, OpenCvReadsWhatWeWrite) {
  std::mt19937 rng(21);
  for (int i = 0; i < 10; ++i) {
    const StereoCalibration c = RandomCalibration(rng);
    char buf[8192];
    const Result<size_t> n = WriteCalibrationYaml(c, buf, sizeof(buf));
    ASSERT_TRUE(n.ok()) << n.status().message();
    cv::FileStorage fs(std::string(buf, *n), cv::FileStorage::READ | cv::FileStorage::MEMORY);
    ASSERT_TRUE(fs.isOpened());
    EXPECT_EQ(static_cast<int>(fs["image_width"]), c.left.width);
    EXPECT_EQ(static_cast<int>(fs["image_height"]), c.left.height);
    cv::Mat K1, D1, K2, D2, R, T;
    fs["K1"] >> K1;
    fs["D1"] >> D1;
    fs["K2"] >> K2;
    fs["D2"] >> D2;
    fs["R"] >> R;
    fs["T"] >> T;
    EXPECT_EQ(MaxAbsDiff(K1, CameraMatrix(c.left)), 0.0);
    EXPECT_EQ(MaxAbsDiff(D1, Distortion(c.left)), 0.0);
    EXPECT_EQ(MaxAbsDiff(K2, CameraMatrix(c.right)), 0.0);
    EXPECT_EQ(MaxAbsDiff(D2, Distortion(c.right)), 0.0);
    cv::Mat R_expected(3, 3, CV_64F), T_expected(3, 1, CV_64F);
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) R_expected.at<double>(r, k) = c.right_R_left(r, k);
      T_expected.at<double>(r) = c.right_t_left_mm(r);
    }
    EXPECT_EQ(MaxAbsDiff(R, R_expected), 0.0);
    EXPECT_EQ(MaxAbsDiff(T, T_expected), 0.0);
  }
}

TEST(CalibrationYamlOpenCv, WeReadWhatOpenCvWrites) {
  std::mt19937 rng(22);
  const StereoCalibration c = RandomCalibration(rng);
  cv::FileStorage fs(
      ".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  cv::Mat R(3, 3, CV_64F), T(3, 1, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) R.at<double>(r, k) = c.right_R_left(r, k);
    T.at<double>(r) = c.right_t_left_mm(r);
  }
  // Key order and extras as in OpenCV's stereo_calib sample plus the image size.
  fs << "calibration_date"
     << "today";
  fs << "image_width" << c.left.width << "image_height" << c.left.height;
  fs << "M1" << CameraMatrix(c.left) << "D1" << Distortion(c.left).t();  // 5x1
  fs << "M2" << CameraMatrix(c.right);
  cv::Mat d2_8 = cv::Mat::zeros(1, 8, CV_64F);  // rational model, unused terms zero
  Distortion(c.right).copyTo(d2_8.colRange(0, 5));
  fs << "D2" << d2_8;
  fs << "R" << R << "T" << T;
  fs << "E" << cv::Mat::eye(3, 3, CV_64F) << "F" << cv::Mat::eye(3, 3, CV_32F);
  fs << "per_view_errors" << std::vector<double>{0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7};
  fs << "board"
     << "{"
     << "width" << 9 << "height" << 6 << "}";
  const std::string text = fs.releaseAndGetString();

  const Result<StereoCalibration> back = ParseCalibrationYaml(text.data(), text.size());
  ASSERT_TRUE(back.ok()) << back.status().message() << "\n" << text;
  EXPECT_DOUBLE_EQ(back->left.fx, c.left.fx);
  EXPECT_DOUBLE_EQ(back->left.cy, c.left.cy);
  EXPECT_DOUBLE_EQ(back->left.k3, c.left.k3);
  EXPECT_DOUBLE_EQ(back->right.fy, c.right.fy);
  EXPECT_DOUBLE_EQ(back->right.p2, c.right.p2);
  EXPECT_DOUBLE_EQ(back->right.k3, c.right.k3);
  EXPECT_LT((back->right_R_left - c.right_R_left).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((back->right_t_left_mm - c.right_t_left_mm).norm(), 1e-12);
}

}  // namespace
}  // namespace sh
