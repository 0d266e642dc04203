// `stereohash calibrate`: stereo calibration from chessboard image pairs, written as the YAML
// file that the recogniser reads (recog/camera/calibration_yaml.hpp). Host only, uses OpenCV.
#include <glob.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "recog/camera/calibration_yaml.hpp"
#include "recog/image/image.hpp"
#include "tools/board_detection.hpp"
#include "tools/chessboard.hpp"
#include "tools/command.hpp"
#include "tools/cv_commands.hpp"

namespace sh::tools {
namespace {

// Bounds of what a user can ask for; each is refused with its name and range.
constexpr size_t kMaxPairs = 200;          // image pairs matched by the globs
constexpr double kMaxTimeLimitS = 3600.0;  // per pair
constexpr double kDefaultTimeLimitS = 10.0;
constexpr double kDefaultMaxRmsPx = 1.0;

void PrintHelp() {
  std::printf(
      "usage: stereohash calibrate --left '<glob>' --right '<glob>' --board <cols>x<rows>\n"
      "                            --square-mm <size> --out <calib.yaml> [--joint]\n"
      "                            [--max-rms-px P] [--force] [--time-limit-s S]\n"
      "Calibrates a stereo pair from chessboard views. The i-th left and i-th right image (each\n"
      "glob sorted by name) form a pair; pairs where the board is not found in both are skipped.\n"
      "  --board         inner corners per row x per column, e.g. 9x6 (2..%d each)\n"
      "  --square-mm     chessboard square size in millimetres (sets the unit of T)\n"
      "  --joint         refine both cameras' intrinsics in the stereo step (default: calibrate\n"
      "                  each camera alone, then only R and T with the intrinsics fixed)\n"
      "  --max-rms-px    largest accepted RMS reprojection error of either camera and of the\n"
      "                  stereo step (default %.1f px); above it nothing is written\n"
      "  --force         write the calibration even above --max-rms-px\n"
      "  --time-limit-s  time to read one pair and search its board (default %.0f s); a pair\n"
      "                  that takes longer is skipped\n"
      "Prints the RMS reprojection error of every pair and of the whole calibration in pixels\n"
      "and writes K1 D1 K2 D2 R T (OpenCV layout). At most %zu pairs, images up to %dx%d.\n",
      kMaxBoardSide, kDefaultMaxRmsPx, kDefaultTimeLimitS, kMaxPairs, kMaxSensorWidth,
      kMaxSensorHeight);
}

std::vector<std::string> Glob(const char* pattern) {
  std::vector<std::string> paths;
  glob_t g;
  if (::glob(pattern, 0, nullptr, &g) == 0) {
    for (size_t i = 0; i < g.gl_pathc; ++i) paths.emplace_back(g.gl_pathv[i]);  // sorted by glob
  }
  globfree(&g);
  return paths;
}

CameraIntrinsics ToIntrinsics(const cv::Mat& K, const cv::Mat& D, cv::Size size) {
  CameraIntrinsics c;
  c.width = size.width;
  c.height = size.height;
  c.fx = K.at<double>(0, 0);
  c.fy = K.at<double>(1, 1);
  c.cx = K.at<double>(0, 2);
  c.cy = K.at<double>(1, 2);
  const double* d = D.ptr<double>();
  c.k1 = d[0];
  c.k2 = d[1];
  c.p1 = d[2];
  c.p2 = d[3];
  c.k3 = D.total() > 4 ? d[4] : 0.0;
  return c;
}

struct CalibrateOptions {
  cv::Size board;
  double square_mm = 0.0;
  bool joint = false;
  double max_rms_px = kDefaultMaxRmsPx;
  bool force = false;
  DetectionLimits limits;
};

struct Views {
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> left, right;
  std::vector<std::string> names;  // "left / right" per used pair
  cv::Size image_size;
};

// Finds the board in every pair; returns false (message printed) on an unusable input.
bool CollectViews(const std::vector<std::string>& left, const std::vector<std::string>& right,
                  const CalibrateOptions& options, Views* views) {
  std::vector<cv::Point3f> board_mm;
  for (int y = 0; y < options.board.height; ++y) {
    for (int x = 0; x < options.board.width; ++x) {
      board_mm.emplace_back(static_cast<float>(x * options.square_mm),
                            static_cast<float>(y * options.square_mm), 0.0f);
    }
  }
  for (size_t i = 0; i < left.size(); ++i) {
    const PairDetection d = DetectBoardPair(left[i], right[i], options.board, options.limits);
    if (d.outcome == PairDetection::Outcome::kFailed) {
      std::fprintf(stderr, "calibrate: pair %s / %s: %s\n", left[i].c_str(), right[i].c_str(),
                   d.message.c_str());
      return false;
    }
    if (d.outcome != PairDetection::Outcome::kFound) {  // no board, or over the time limit
      std::printf("skipped pair %s / %s: %s\n", left[i].c_str(), right[i].c_str(),
                  d.message.c_str());
      continue;
    }
    if (views->image_size.empty()) views->image_size = d.image_size;
    if (d.image_size != views->image_size) {
      std::fprintf(stderr, "calibrate: '%s' / '%s' differ in size from the first pair %dx%d\n",
                   left[i].c_str(), right[i].c_str(), views->image_size.width,
                   views->image_size.height);
      return false;
    }
    views->object.push_back(board_mm);
    views->left.push_back(d.left);
    views->right.push_back(d.right);
    views->names.push_back(left[i] + " / " + right[i]);
  }
  return true;
}

// RMS distance between the board corners and their reprojection, per view.
std::vector<double> PerViewRms(const Views& v, const std::vector<std::vector<cv::Point2f>>& seen,
                               const cv::Mat& K, const cv::Mat& D,
                               const std::vector<cv::Mat>& rvecs,
                               const std::vector<cv::Mat>& tvecs) {
  std::vector<double> rms;
  for (size_t i = 0; i < v.object.size(); ++i) {
    std::vector<cv::Point2f> projected;
    cv::projectPoints(v.object[i], rvecs[i], tvecs[i], K, D, projected);
    const double norm = cv::norm(seen[i], projected, cv::NORM_L2);
    rms.push_back(norm / std::sqrt(double(projected.size())));
  }
  return rms;
}

int Calibrate(const char* left_glob, const char* right_glob, const char* out_path,
              const CalibrateOptions& options) {
  const std::vector<std::string> left = Glob(left_glob), right = Glob(right_glob);
  if (left.empty() || right.empty()) {
    std::fprintf(stderr, "calibrate: no images match '%s'\n",
                 left.empty() ? left_glob : right_glob);
    return 1;
  }
  if (left.size() != right.size()) {
    std::fprintf(stderr, "calibrate: %zu left but %zu right images; they must pair up\n",
                 left.size(), right.size());
    return 1;
  }
  if (left.size() > kMaxPairs) {
    std::fprintf(stderr, "calibrate: %zu pairs match; at most %zu are used in one calibration\n",
                 left.size(), kMaxPairs);
    return 1;
  }
  Views views;
  if (!CollectViews(left, right, options, &views)) return 1;
  std::printf("using %zu of %zu pairs\n", views.object.size(), left.size());
  if (views.object.size() < 3) {
    std::fprintf(stderr, "calibrate: need the board in at least 3 pairs, found %zu\n",
                 views.object.size());
    return 1;
  }

  cv::Mat K1, D1, K2, D2, R, T, E, F, stereo_per_view;
  std::vector<cv::Mat> rvecs_left, tvecs_left, rvecs_right, tvecs_right;
  const double rms_left = cv::calibrateCamera(views.object, views.left, views.image_size, K1, D1,
                                              rvecs_left, tvecs_left);
  const double rms_right = cv::calibrateCamera(views.object, views.right, views.image_size, K2, D2,
                                               rvecs_right, tvecs_right);
  const std::vector<double> per_view_left =
      PerViewRms(views, views.left, K1, D1, rvecs_left, tvecs_left);
  const std::vector<double> per_view_right =
      PerViewRms(views, views.right, K2, D2, rvecs_right, tvecs_right);
  const int flags = options.joint ? cv::CALIB_USE_INTRINSIC_GUESS : cv::CALIB_FIX_INTRINSIC;
  const double rms_stereo = cv::stereoCalibrate(
      views.object, views.left, views.right, K1, D1, K2, D2, views.image_size, R, T, E, F,
      stereo_per_view, flags,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-6));

  std::printf("RMS reprojection error per pair (px): left camera, right camera, stereo l / r\n");
  for (size_t i = 0; i < views.object.size(); ++i) {
    const double sl = stereo_per_view.at<double>(int(i), 0);
    const double sr = stereo_per_view.at<double>(int(i), 1);
    const bool over = per_view_left[i] > options.max_rms_px ||
                      per_view_right[i] > options.max_rms_px || sl > options.max_rms_px ||
                      sr > options.max_rms_px;
    std::printf("  %s: %.4f, %.4f, %.4f / %.4f%s\n", views.names[i].c_str(), per_view_left[i],
                per_view_right[i], sl, sr, over ? "  (above the limit)" : "");
  }
  StereoCalibration calib;
  calib.left = ToIntrinsics(K1, D1, views.image_size);
  calib.right = ToIntrinsics(K2, D2, views.image_size);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) calib.right_R_left(r, c) = R.at<double>(r, c);
    calib.right_t_left_mm(r) = T.at<double>(r);
  }
  std::printf("left camera RMS reprojection error: %.4f px\n", rms_left);
  std::printf("right camera RMS reprojection error: %.4f px\n", rms_right);
  std::printf("stereo RMS reprojection error: %.4f px\n", rms_stereo);
  std::printf("baseline: %.3f mm\n", calib.right_t_left_mm.norm());
  const double worst = std::max({rms_left, rms_right, rms_stereo});
  if (!(worst <= options.max_rms_px)) {
    if (!options.force) {
      std::fprintf(stderr,
                   "calibrate: RMS reprojection error %.4f px exceeds --max-rms-px %g: the board "
                   "views disagree (another board size or square, a board that moved between "
                   "the left and right image, pairs out of order?); the pairs above the limit "
                   "are marked. Nothing written; --force writes it anyway\n",
                   worst, options.max_rms_px);
      return 1;
    }
    std::printf(
        "warning: RMS reprojection error %.4f px exceeds --max-rms-px %g; written "
        "because of --force\n",
        worst, options.max_rms_px);
  }
  static char text[kMaxCalibrationYamlBytes];
  const Result<size_t> length = WriteCalibrationYaml(calib, text, sizeof(text));
  if (!length.ok()) {
    std::fprintf(stderr, "calibrate: the result is not a usable calibration: %s; nothing written\n",
                 length.status().message());
    return 1;
  }
  FILE* out = std::fopen(out_path, "wb");
  if (out == nullptr || std::fwrite(text, 1, *length, out) != *length) {
    std::fprintf(stderr, "calibrate: cannot write '%s': %s\n", out_path, std::strerror(errno));
    if (out != nullptr) std::fclose(out);
    return 1;
  }
  if (std::fclose(out) != 0) {
    std::fprintf(stderr, "calibrate: cannot write '%s': %s\n", out_path, std::strerror(errno));
    return 1;
  }
  std::printf("wrote %s\n", out_path);
  return 0;
}

int RunCalibrate(int argc, char** argv) {
  const char* left = nullptr;
  const char* right = nullptr;
  const char* out = nullptr;
  int cols = 0, rows = 0;
  CalibrateOptions options;
  options.limits.time_limit_s = kDefaultTimeLimitS;
  options.limits.max_width = kMaxSensorWidth;
  options.limits.max_height = kMaxSensorHeight;
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    const bool has_value = i + 1 < argc;
    if (std::strcmp(a, "--help") == 0 || std::strcmp(a, "-h") == 0) {
      PrintHelp();
      return 0;
    } else if (std::strcmp(a, "--joint") == 0) {
      options.joint = true;
    } else if (std::strcmp(a, "--force") == 0) {
      options.force = true;
    } else if (std::strcmp(a, "--left") == 0 && has_value) {
      left = argv[++i];
    } else if (std::strcmp(a, "--right") == 0 && has_value) {
      right = argv[++i];
    } else if (std::strcmp(a, "--out") == 0 && has_value) {
      out = argv[++i];
    } else if (std::strcmp(a, "--board") == 0 && has_value) {
      cv::Size board;
      if (!ParseBoardSize(argv[++i], &board)) {
        std::fprintf(stderr,
                     "calibrate: --board wants <cols>x<rows> inner corners, each 2..%d, e.g. 9x6 "
                     "(got '%.16s')\n",
                     kMaxBoardSide, argv[i]);
        return 2;
      }
      cols = board.width;
      rows = board.height;
    } else if (std::strcmp(a, "--square-mm") == 0 && has_value) {
      if (!ParseSquareMm(argv[++i], &options.square_mm)) {
        std::fprintf(stderr, "calibrate: --square-mm wants a size in millimetres, %g..%g\n",
                     kMinSquareMm, kMaxSquareMm);
        return 2;
      }
    } else if (std::strcmp(a, "--max-rms-px") == 0 && has_value) {
      if (!ParseNumber(argv[++i], 1e-3, 100.0, &options.max_rms_px)) {
        std::fprintf(stderr, "calibrate: --max-rms-px wants pixels, 0.001..100\n");
        return 2;
      }
    } else if (std::strcmp(a, "--time-limit-s") == 0 && has_value) {
      if (!ParseNumber(argv[++i], 1e-3, kMaxTimeLimitS, &options.limits.time_limit_s)) {
        std::fprintf(stderr, "calibrate: --time-limit-s wants seconds, 0.001..%g\n",
                     kMaxTimeLimitS);
        return 2;
      }
    } else {
      std::fprintf(stderr, "calibrate: unknown or incomplete option '%s'\n\n", a);
      PrintHelp();
      return 2;
    }
  }
  if (left == nullptr || right == nullptr || out == nullptr || cols == 0 ||
      options.square_mm == 0.0) {
    std::fprintf(stderr,
                 "calibrate: --left, --right, --board, --square-mm and --out are required\n\n");
    PrintHelp();
    return 2;
  }
  options.board = cv::Size(cols, rows);
  try {
    return Calibrate(left, right, out, options);
  } catch (const cv::Exception& e) {
    std::fprintf(stderr, "calibrate: OpenCV failed: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "calibrate: out of memory\n");
    return 1;
  }
}

}  // namespace

SH_REGISTER_COMMAND(calibrate, kCalibrateSummary, RunCalibrate);

}  // namespace sh::tools
