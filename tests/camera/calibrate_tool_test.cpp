// `stereohash calibrate` on OpenCV's sample stereo pairs (Debian package opencv-doc), compared
// with a calibration that OpenCV computes here directly along the route of its stereo_calib
// sample, and checked through our own geometry (triangulated board squares are square-mm wide).
#include <gtest/gtest.h>
#include <sys/stat.h>
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
#include "recog/camera/table_yaml.hpp"
#include "recog/stereo/triangulation.hpp"

namespace sh {
namespace {

const char kDataDir[] = "/usr/share/doc/opencv-doc/examples/data";
const int kPairs[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14};  // there is no pair 10
const cv::Size kBoard(9, 6);
constexpr double kSquareMm = 25.0;

// OpenCV spreads its loops over a thread pool of its own, in code that ThreadSanitizer does not
// instrument: here it runs them on the calling thread, so this program starts no thread and the
// thread guard proves it. The `stereohash` it starts runs no thread of ours either.
[[maybe_unused]] const bool kOpenCvOnTheCallingThread = [] {
  cv::setNumThreads(0);
  return true;
}();

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
int RunTool(const std::string& args, std::string* output, const char* command_name = "calibrate") {
  const std::string command =
      std::string(STEREOHASH_EXE) + " " + command_name + " " + args + " 2>&1";
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

// A fresh folder under the test's temporary directory.
std::string TempDir(const char* name) {
  std::string dir = TempPath(name);
  (void)std::system(("rm -rf '" + dir + "' && mkdir -p '" + dir + "'").c_str());
  return dir;
}

// Links sample pair i into `dir` as left<NN>.jpg / right<NN>.jpg, with the right image of
// sample pair `right_from` (the same pair unless a test mixes them up).
void LinkPair(const std::string& dir, int name, int i, int right_from) {
  char l[32], r[32];
  std::snprintf(l, sizeof(l), "/left%02d.jpg", name);
  std::snprintf(r, sizeof(r), "/right%02d.jpg", name);
  ASSERT_EQ(symlink(ImagePath("left", i).c_str(), (dir + l).c_str()), 0);
  ASSERT_EQ(symlink(ImagePath("right", right_from).c_str(), (dir + r).c_str()), 0);
}

std::string Globs(const std::string& dir) {
  return "--left '" + dir + "/left*.jpg' --right '" + dir +
         "/right*.jpg' --board 9x6 --square-mm 25";
}

TEST(CalibrateTool, ReprojectionErrorAboveTheLimitIsRefusedUnlessForced) {
  if (!SampleImagesPresent()) GTEST_SKIP() << "OpenCV sample stereo pairs not found";
  const std::string data(kDataDir);
  const std::string out = TempPath("forced.yaml");
  const std::string args = "--left '" + data + "/left[0-9]*.jpg' --right '" + data +
                           "/right[0-9]*.jpg' --board 9x6 --square-mm 25 --out " + out;
  std::remove(out.c_str());
  std::string output;
  // The samples reach about 0.45 px: a 0.3 px limit refuses them.
  EXPECT_EQ(RunTool(args + " --max-rms-px 0.3", &output), 1) << output;
  EXPECT_NE(output.find("exceeds --max-rms-px 0.3"), std::string::npos) << output;
  EXPECT_NE(output.find("left02.jpg / " + data + "/right02.jpg: 1.2"), std::string::npos)
      << "per-pair errors, the worst pair marked: " << output;
  EXPECT_NE(output.find("(above the limit)"), std::string::npos) << output;
  EXPECT_NE(access(out.c_str(), F_OK), 0) << "nothing written";
  output.clear();
  EXPECT_EQ(RunTool(args + " --max-rms-px 0.3 --force", &output), 0) << output;
  EXPECT_NE(output.find("written because of --force"), std::string::npos) << output;
  EXPECT_EQ(access(out.c_str(), F_OK), 0);
  std::remove(out.c_str());
}

TEST(CalibrateTool, InconsistentBoardViewsAreRefused) {
  if (!SampleImagesPresent()) GTEST_SKIP() << "OpenCV sample stereo pairs not found";
  // Each left image with the right image of another pair: both boards are found, but the
  // stereo geometry cannot explain them.
  const std::string dir = TempDir("mixed");
  const int pairs[] = {1, 3, 4, 6, 7, 8, 9, 11};
  for (int k = 0; k < 8; ++k) LinkPair(dir, k, pairs[k], pairs[(k + 3) % 8]);
  std::string output;
  EXPECT_EQ(RunTool(Globs(dir) + " --out " + dir + "/calib.yaml", &output), 1) << output;
  EXPECT_NE(output.find("exceeds --max-rms-px 1"), std::string::npos) << output;
  EXPECT_NE(access((dir + "/calib.yaml").c_str(), F_OK), 0);
  (void)std::system(("rm -rf '" + dir + "'").c_str());
}

TEST(CalibrateTool, APairThatNeverArrivesIsSkippedAfterTheTimeLimit) {
  if (!SampleImagesPresent()) GTEST_SKIP() << "OpenCV sample stereo pairs not found";
  // left00.jpg is a FIFO nobody writes to: reading it blocks for ever, like an image the
  // detector never finishes with.
  const std::string dir = TempDir("fifo");
  ASSERT_EQ(mkfifo((dir + "/left00.jpg").c_str(), 0600), 0);
  ASSERT_EQ(symlink(ImagePath("right", 1).c_str(), (dir + "/right00.jpg").c_str()), 0);
  for (int i : {1, 3, 4, 6, 7}) LinkPair(dir, i, i, i);
  // The FIFO never ends, so any limit shows the skip; the real pairs must finish well inside
  // it even under ThreadSanitizer on a busy machine (about 2 s a pair there), hence 10 s.
  std::string output;
  RunTool(Globs(dir) + " --time-limit-s 10 --out " + dir + "/calib.yaml", &output);
  EXPECT_NE(output.find("left00.jpg / " + dir +
                        "/right00.jpg: reading and searching the pair "
                        "took longer than 10 s"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("using 5 of 6 pairs"), std::string::npos) << output;
  (void)std::system(("rm -rf '" + dir + "'").c_str());
}

TEST(CalibrateTool, ImagesLargerThanTheLargestSensorAreRefused) {
  const std::string dir = TempDir("large");
  const cv::Mat big(2200, 2800, CV_8UC1, cv::Scalar(128));
  ASSERT_TRUE(cv::imwrite(dir + "/left00.png", big));
  ASSERT_TRUE(cv::imwrite(dir + "/right00.png", big));
  std::string output;
  EXPECT_EQ(RunTool("--left '" + dir + "/left*.png' --right '" + dir +
                        "/right*.png' --board 9x6 --square-mm 25 --out " + dir + "/c.yaml",
                    &output),
            1);
  EXPECT_NE(output.find("is 2800x2200, larger than the 2592x2048"), std::string::npos) << output;
  (void)std::system(("rm -rf '" + dir + "'").c_str());
}

TEST(CalibrateTool, SizesAUserGivesAreBounded) {
  std::string output;
  EXPECT_EQ(RunTool("--left a --right b --board 100000x100000 --square-mm 25 --out x", &output), 2);
  EXPECT_NE(output.find("each 2..64"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(RunTool("--left a --right b --board 9x6 --square-mm 1e9 --out x", &output), 2);
  EXPECT_NE(output.find("0.001..1000"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(
      RunTool("--left a --right b --board 9x6 --square-mm 25 --time-limit-s 1e9 --out x", &output),
      2);
  EXPECT_NE(output.find("--time-limit-s"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(
      RunTool("--left a --right b --board 9x6 --square-mm 25 --max-rms-px -1 --out x", &output), 2);
  EXPECT_NE(output.find("--max-rms-px"), std::string::npos) << output;
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

// A chessboard of kBoard inner corners lying on a table, seen by an undistorted stereo pair:
// each image is the board texture warped by the homography of its camera.
cv::Mat RenderBoard(const CameraIntrinsics& cam, const RigidTransform& cam_T_table) {
  const int px_per_square = 40, margin = 1;  // texture: squares plus a white margin square
  const int cols = kBoard.width + 1 + 2 * margin, rows = kBoard.height + 1 + 2 * margin;
  cv::Mat texture(rows * px_per_square, cols * px_per_square, CV_8U, cv::Scalar(230));
  for (int r = margin; r < rows - margin; ++r) {
    for (int c = margin; c < cols - margin; ++c) {
      if ((r + c) % 2 == 0) {
        texture(cv::Rect(c * px_per_square, r * px_per_square, px_per_square, px_per_square)) = 25;
      }
    }
  }
  // Texture pixel (u, v) -> table point (mm): the first inner corner is the table origin.
  const double mm_per_px = kSquareMm / px_per_square;
  const double origin_px = (margin + 1) * px_per_square;
  cv::Matx33d table_from_texture(mm_per_px, 0, -origin_px * mm_per_px, 0, mm_per_px,
                                 -origin_px * mm_per_px, 0, 0, 1);
  // Table plane (z = 0) -> image: K [r1 r2 t].
  const Eigen::Matrix3f& R = cam_T_table.R;
  const Eigen::Vector3f& t = cam_T_table.t_mm;
  cv::Matx33d Rt(R(0, 0), R(0, 1), t.x(), R(1, 0), R(1, 1), t.y(), R(2, 0), R(2, 1), t.z());
  cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  cv::Mat image;
  cv::warpPerspective(texture, image, cv::Mat(K * Rt * table_from_texture),
                      cv::Size(cam.width, cam.height), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                      cv::Scalar(120));
  return image;
}

TEST(CalibrateTableTool, RecoversTheTablePoseOfARenderedBoard) {
  StereoCalibration calib;
  for (CameraIntrinsics* c : {&calib.left, &calib.right}) {
    c->width = 756, c->height = 581;
    c->fx = c->fy = 1136.4, c->cx = 377.5, c->cy = 290.0;
  }
  calib.right_R_left = Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitY()).toRotationMatrix();
  calib.right_t_left_mm = Eigen::Vector3d(-118.0, -2.0, 15.0);
  // The table 450 mm in front, tilted 35 deg about the camera x axis, z towards the camera.
  RigidTransform left_T_table;
  left_T_table.R = (Eigen::AngleAxisf(float(M_PI) - 0.6f, Eigen::Vector3f::UnitX()) *
                    Eigen::AngleAxisf(0.2f, Eigen::Vector3f::UnitZ()))
                       .toRotationMatrix();
  left_T_table.t_mm = Eigen::Vector3f(-110.0f, 60.0f, 430.0f);
  RigidTransform right_T_left;
  right_T_left.R = calib.right_R_left.cast<float>();
  right_T_left.t_mm = calib.right_t_left_mm.cast<float>();

  const std::string left = TempPath("table_left.png"), right = TempPath("table_right.png");
  const std::string yaml = TempPath("table_calib.yaml"), out = TempPath("table.yaml");
  ASSERT_TRUE(cv::imwrite(left, RenderBoard(calib.left, left_T_table)));
  ASSERT_TRUE(cv::imwrite(right, RenderBoard(calib.right, right_T_left * left_T_table)));
  char text[8192];
  const Result<size_t> n = WriteCalibrationYaml(calib, text, sizeof(text));
  ASSERT_TRUE(n.ok());
  std::ofstream(yaml) << std::string(text, *n);

  std::string output;
  const std::string args = "--calib " + yaml + " --left " + left + " --right " + right +
                           " --board 9x6 --square-mm 25 --out " + out;
  ASSERT_EQ(RunTool(args, &output, "calibrate-table"), 0) << output;
  std::ifstream in(out);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const Result<RigidTransform> pose = ParseTableYaml(written.data(), written.size());
  ASSERT_TRUE(pose.ok()) << pose.status().message();
  // The table's origin is the corner OpenCV lists first: one of the board's four outer inner
  // corners. The normal is the rendering's; the axes in the plane may turn with the board.
  float nearest = 1e9f;
  for (float x : {0.0f, 8 * float(kSquareMm)}) {
    for (float y : {0.0f, 5 * float(kSquareMm)}) {
      nearest = std::min(nearest, (pose->t_mm - left_T_table * Eigen::Vector3f(x, y, 0)).norm());
    }
  }
  EXPECT_LT(nearest, 1.0f) << output;
  EXPECT_GT(pose->R.col(2).dot(left_T_table.R.col(2)), std::cos(0.3f * float(M_PI) / 180.0f))
      << output;
  // Points of the table plane lie at z = 0 in the measured frame too.
  const Eigen::Vector3f on_table = left_T_table * Eigen::Vector3f(80, 40, 0);
  EXPECT_LT(std::fabs((pose->Inverse() * on_table).z()), 0.5f);

  output.clear();
  EXPECT_EQ(RunTool("--calib " + yaml + " --left " + left + " --right " + right +
                        " --board 9x6 --square-mm 40 --out " + out,
                    &output, "calibrate-table"),
            1)
      << output;
  EXPECT_NE(output.find("square"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(RunTool("--calib " + yaml + " --left " + left +
                        " --right /nonexistent.png "
                        "--board 9x6 --square-mm 25 --out " +
                        out,
                    &output, "calibrate-table"),
            1);
  EXPECT_NE(output.find("/nonexistent.png"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(RunTool("--calib " + yaml + " --left " + left, &output, "calibrate-table"), 2);
  EXPECT_NE(output.find("required"), std::string::npos) << output;
  std::remove(left.c_str());
  std::remove(right.c_str());
  std::remove(yaml.c_str());
  std::remove(out.c_str());
}

}  // namespace
}  // namespace sh
