// `stereohash calibrate` on OpenCV's sample stereo pairs (Debian package opencv-doc), compared
// with a calibration that OpenCV computes here directly along the route of its stereo_calib
// sample, and checked through our own geometry (triangulated board squares are square-mm wide).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "recog/camera/calibration_yaml.hpp"
#include "recog/stereo/triangulation.hpp"

namespace sh {
namespace {

const char kDataDir[] = "/usr/share/doc/opencv-doc/examples/data";
const int kPairs[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14};  // there is no pair 10
const cv::Size kBoard(9, 6);
constexpr double kSquareMm = 25.0;

std::string ImagePath(const char* side, int i) {
  char name[64];
  std::snprintf(name, sizeof(name), "%s/%s%02d.jpg", kDataDir, side, i);
  return name;
}

bool SampleImagesPresent() {
  for (int i : kPairs) {
    if (access(ImagePath("left", i).c_str(), R_OK) != 0 ||
        access(ImagePath("right", i).c_str(), R_OK) != 0) {
      return false;
    }
  }
  return true;
}

// Runs the tool; returns its exit status and stdout (stderr merged).
int RunTool(const std::string& args, std::string* output) {
  const std::string command = std::string(STEREOHASH_EXE) + " calibrate " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return -1;
  char buf[512];
  while (std::fgets(buf, sizeof(buf), pipe) != nullptr) *output += buf;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

double ValueAfter(const std::string& text, const std::string& label) {
  const size_t at = text.find(label);
  if (at == std::string::npos) return -1.0;
  return std::strtod(text.c_str() + at + label.size(), nullptr);
}

std::string TempPath(const char* name) {
  return std::string(::testing::TempDir()) + "/stereohash_" + std::to_string(getpid()) + "_" + name;
}

struct BoardViews {
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> left, right;
  cv::Size image_size;
};

BoardViews DetectBoards() {
  BoardViews v;
  std::vector<cv::Point3f> board;
  for (int y = 0; y < kBoard.height; ++y) {
    for (int x = 0; x < kBoard.width; ++x) board.emplace_back(x * kSquareMm, y * kSquareMm, 0.f);
  }
  for (int i : kPairs) {
    const cv::Mat l = cv::imread(ImagePath("left", i), cv::IMREAD_GRAYSCALE);
    const cv::Mat r = cv::imread(ImagePath("right", i), cv::IMREAD_GRAYSCALE);
    std::vector<cv::Point2f> lc, rc;
    if (!cv::findChessboardCorners(l, kBoard, lc) || !cv::findChessboardCorners(r, kBoard, rc)) {
      continue;
    }
    const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
    cv::cornerSubPix(l, lc, cv::Size(11, 11), cv::Size(-1, -1), criteria);
    cv::cornerSubPix(r, rc, cv::Size(11, 11), cv::Size(-1, -1), criteria);
    v.object.push_back(board);
    v.left.push_back(lc);
    v.right.push_back(rc);
    v.image_size = l.size();
  }
  return v;
}

TEST(CalibrateTool, SamplePairsAgainstOpenCvStereoCalibrate) {
  if (!SampleImagesPresent()) {
    GTEST_SKIP() << "OpenCV sample stereo pairs not found in " << kDataDir
                 << " (apt-get install opencv-doc)";
  }
  const std::string yaml_path = TempPath("calib.yaml");
  std::string output;
  const std::string data(kDataDir);
  const int exit_code =
      RunTool("--left '" + data + "/left[0-9]*.jpg' --right '" + data +
                  "/right[0-9]*.jpg' --board 9x6 --square-mm 25 --out " + yaml_path,
              &output);
  ASSERT_EQ(exit_code, 0) << output;
  const double tool_rms = ValueAfter(output, "stereo RMS reprojection error: ");
  ASSERT_GT(tool_rms, 0.0) << output;
  EXPECT_LT(tool_rms, 1.0) << output;

  std::ifstream file(yaml_path);
  std::stringstream text;
  text << file.rdbuf();
  std::remove(yaml_path.c_str());
  const std::string yaml = text.str();
  const Result<StereoCalibration> calib = ParseCalibrationYaml(yaml.data(), yaml.size());
  ASSERT_TRUE(calib.ok()) << calib.status().message();
  EXPECT_EQ(calib->left.width, 640);
  EXPECT_EQ(calib->left.height, 480);

  // OpenCV's own route (as in its stereo_calib sample): joint stereo calibration from an initial
  // camera matrix, same focal length, no tangential distortion.
  const BoardViews views = DetectBoards();
  ASSERT_GE(views.object.size(), 10u);
  cv::Mat K1 = cv::initCameraMatrix2D(views.object, views.left, views.image_size, 0);
  cv::Mat K2 = cv::initCameraMatrix2D(views.object, views.right, views.image_size, 0);
  cv::Mat D1, D2, R, T, E, F;
  const double opencv_rms = cv::stereoCalibrate(
      views.object, views.left, views.right, K1, D1, K2, D2, views.image_size, R, T, E, F,
      cv::CALIB_FIX_ASPECT_RATIO | cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_USE_INTRINSIC_GUESS |
          cv::CALIB_SAME_FOCAL_LENGTH | cv::CALIB_FIX_K3,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-5));
  std::printf("stereo RMS reprojection error: stereohash calibrate %.4f px, OpenCV joint %.4f px\n",
              tool_rms, opencv_rms);
  const Eigen::Vector3d T_opencv(T.at<double>(0), T.at<double>(1), T.at<double>(2));
  std::printf("baseline: stereohash calibrate %.3f mm, OpenCV joint %.3f mm\n",
              calib->right_t_left_mm.norm(), T_opencv.norm());
  RecordProperty("tool_rms_px", std::to_string(tool_rms));
  RecordProperty("opencv_rms_px", std::to_string(opencv_rms));
  EXPECT_LT(opencv_rms, 1.0);
  // Two calibration routes on the same 13 views agree on the geometry to a few per cent.
  EXPECT_NEAR(calib->right_t_left_mm.norm(), T_opencv.norm(), 0.03 * T_opencv.norm());
  EXPECT_NEAR(calib->left.fx, K1.at<double>(0, 0), 0.03 * K1.at<double>(0, 0));
  Eigen::Matrix3d R_opencv;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R_opencv(r, c) = R.at<double>(r, c);
  }
  const double angle_deg =
      Eigen::AngleAxisd(R_opencv.transpose() * calib->right_R_left).angle() * 180.0 / M_PI;
  EXPECT_LT(angle_deg, 1.0);

  // Our own geometry with the tool's calibration: neighbouring board corners triangulate
  // kSquareMm apart.
  double sum = 0.0, sum_sq = 0.0, worst = 0.0;
  int n = 0;
  for (size_t v = 0; v < views.left.size(); ++v) {
    std::vector<Eigen::Vector3d> p;
    for (size_t k = 0; k < views.left[v].size(); ++k) {
      RayMidpoint m;
      ASSERT_TRUE(TriangulatePixels(*calib, {views.left[v][k].x, views.left[v][k].y},
                                    {views.right[v][k].x, views.right[v][k].y}, &m));
      p.push_back(m.p_mm);
    }
    for (int y = 0; y < kBoard.height; ++y) {
      for (int x = 0; x + 1 < kBoard.width; ++x) {
        const double d = (p[y * kBoard.width + x + 1] - p[y * kBoard.width + x]).norm();
        sum += d;
        sum_sq += (d - kSquareMm) * (d - kSquareMm);
        worst = std::max(worst, std::fabs(d - kSquareMm));
        ++n;
      }
    }
  }
  const double rms = std::sqrt(sum_sq / n);
  std::printf(
      "triangulated square: mean %.3f mm, RMS deviation %.3f mm, worst %.3f mm over %d "
      "squares\n",
      sum / n, rms, worst, n);
  // Depth noise of single corners (0.5 px at ~400 mm with an 84 mm baseline is ~2 mm) shows in
  // the worst square; the mean and RMS reflect the calibration.
  EXPECT_NEAR(sum / n, kSquareMm, 0.25);
  EXPECT_LT(rms, 1.5);
}

TEST(CalibrateTool, BadArgumentsGiveClearErrors) {
  std::string output;
  EXPECT_EQ(RunTool("--left '/nonexistent/left*.jpg' --right '/nonexistent/right*.jpg' "
                    "--board 9x6 --square-mm 25 --out /dev/null",
                    &output),
            1);
  EXPECT_NE(output.find("no images match"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(RunTool("--left a --right b --board 9by6 --square-mm 25 --out x", &output), 2);
  EXPECT_NE(output.find("--board"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(RunTool("--left a --right b --board 9x6 --out x", &output), 2);
  EXPECT_NE(output.find("required"), std::string::npos) << output;
}

}  // namespace
}  // namespace sh
