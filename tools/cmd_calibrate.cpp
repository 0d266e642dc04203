// `stereohash calibrate`: stereo calibration from chessboard image pairs, written as the YAML
// file that the recogniser reads (recog/camera/calibration_yaml.hpp). Host only, uses OpenCV.
#include <glob.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "recog/camera/calibration_yaml.hpp"
#include "tools/chessboard.hpp"
#include "tools/command.hpp"

namespace sh::tools {
namespace {

void PrintHelp() {
  std::printf(
      "usage: stereohash calibrate --left '<glob>' --right '<glob>' --board <cols>x<rows>\n"
      "                            --square-mm <size> --out <calib.yaml> [--joint]\n"
      "Calibrates a stereo pair from chessboard views. The i-th left and i-th right image (each\n"
      "glob sorted by name) form a pair; pairs where the board is not found in both are skipped.\n"
      "  --board      inner corners per row x per column, e.g. 9x6\n"
      "  --square-mm  chessboard square size in millimetres (sets the unit of T)\n"
      "  --joint      refine both cameras' intrinsics in the stereo step (default: calibrate\n"
      "               each camera alone, then only R and T with the intrinsics fixed)\n"
      "Prints the RMS reprojection errors in pixels and writes K1 D1 K2 D2 R T (OpenCV layout).\n");
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

int Calibrate(const char* left_glob, const char* right_glob, cv::Size board, double square_mm,
              const char* out_path, bool joint) {
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

  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> left_points, right_points;
  std::vector<cv::Point3f> board_mm;
  for (int y = 0; y < board.height; ++y) {
    for (int x = 0; x < board.width; ++x) {
      board_mm.emplace_back(static_cast<float>(x * square_mm), static_cast<float>(y * square_mm),
                            0.0f);
    }
  }
  cv::Size image_size;
  for (size_t i = 0; i < left.size(); ++i) {
    const cv::Mat l = cv::imread(left[i], cv::IMREAD_GRAYSCALE);
    const cv::Mat r = cv::imread(right[i], cv::IMREAD_GRAYSCALE);
    if (l.empty() || r.empty()) {
      std::fprintf(stderr, "calibrate: cannot read '%s'\n", (l.empty() ? left : right)[i].c_str());
      return 1;
    }
    if (image_size.empty()) image_size = l.size();
    if (l.size() != image_size || r.size() != image_size) {
      std::fprintf(stderr, "calibrate: '%s' / '%s' differ in size from the first image %dx%d\n",
                   left[i].c_str(), right[i].c_str(), image_size.width, image_size.height);
      return 1;
    }
    std::vector<cv::Point2f> lc, rc;
    if (!FindBoard(l, board, &lc) || !FindBoard(r, board, &rc)) {
      std::printf("skipped pair %s / %s: board not found in both\n", left[i].c_str(),
                  right[i].c_str());
      continue;
    }
    object_points.push_back(board_mm);
    left_points.push_back(lc);
    right_points.push_back(rc);
  }
  std::printf("using %zu of %zu pairs\n", object_points.size(), left.size());
  if (object_points.size() < 3) {
    std::fprintf(stderr, "calibrate: need the board in at least 3 pairs, found %zu\n",
                 object_points.size());
    return 1;
  }

  cv::Mat K1, D1, K2, D2, R, T, E, F;
  std::vector<cv::Mat> rvecs, tvecs;
  const double rms_left =
      cv::calibrateCamera(object_points, left_points, image_size, K1, D1, rvecs, tvecs);
  const double rms_right =
      cv::calibrateCamera(object_points, right_points, image_size, K2, D2, rvecs, tvecs);
  const int flags = joint ? cv::CALIB_USE_INTRINSIC_GUESS : cv::CALIB_FIX_INTRINSIC;
  const double rms_stereo = cv::stereoCalibrate(
      object_points, left_points, right_points, K1, D1, K2, D2, image_size, R, T, E, F, flags,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-6));

  StereoCalibration calib;
  calib.left = ToIntrinsics(K1, D1, image_size);
  calib.right = ToIntrinsics(K2, D2, image_size);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) calib.right_R_left(r, c) = R.at<double>(r, c);
    calib.right_t_left_mm(r) = T.at<double>(r);
  }
  static char text[kMaxCalibrationYamlBytes];
  const Result<size_t> length = WriteCalibrationYaml(calib, text, sizeof(text));
  if (!length.ok()) {
    std::fprintf(stderr, "calibrate: %s\n", length.status().message());
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
  std::printf("left camera RMS reprojection error: %.4f px\n", rms_left);
  std::printf("right camera RMS reprojection error: %.4f px\n", rms_right);
  std::printf("stereo RMS reprojection error: %.4f px\n", rms_stereo);
  std::printf("baseline: %.3f mm\n", calib.right_t_left_mm.norm());
  std::printf("wrote %s\n", out_path);
  return 0;
}

int RunCalibrate(int argc, char** argv) {
  const char* left = nullptr;
  const char* right = nullptr;
  const char* out = nullptr;
  int cols = 0, rows = 0;
  double square_mm = 0.0;
  bool joint = false;
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    const bool has_value = i + 1 < argc;
    if (std::strcmp(a, "--help") == 0 || std::strcmp(a, "-h") == 0) {
      PrintHelp();
      return 0;
    } else if (std::strcmp(a, "--joint") == 0) {
      joint = true;
    } else if (std::strcmp(a, "--left") == 0 && has_value) {
      left = argv[++i];
    } else if (std::strcmp(a, "--right") == 0 && has_value) {
      right = argv[++i];
    } else if (std::strcmp(a, "--out") == 0 && has_value) {
      out = argv[++i];
    } else if (std::strcmp(a, "--board") == 0 && has_value) {
      cv::Size board;
      if (!ParseBoardSize(argv[++i], &board)) {
        std::fprintf(stderr, "calibrate: --board wants <cols>x<rows> inner corners, e.g. 9x6\n");
        return 2;
      }
      cols = board.width;
      rows = board.height;
    } else if (std::strcmp(a, "--square-mm") == 0 && has_value) {
      if (!ParseSquareMm(argv[++i], &square_mm)) {
        std::fprintf(stderr, "calibrate: --square-mm wants a positive size in millimetres\n");
        return 2;
      }
    } else {
      std::fprintf(stderr, "calibrate: unknown or incomplete option '%s'\n\n", a);
      PrintHelp();
      return 2;
    }
  }
  if (left == nullptr || right == nullptr || out == nullptr || cols == 0 || square_mm == 0.0) {
    std::fprintf(stderr,
                 "calibrate: --left, --right, --board, --square-mm and --out are required\n\n");
    PrintHelp();
    return 2;
  }
  try {
    return Calibrate(left, right, cv::Size(cols, rows), square_mm, out, joint);
  } catch (const cv::Exception& e) {
    std::fprintf(stderr, "calibrate: OpenCV failed: %s\n", e.what());
    return 1;
  }
}

}  // namespace

SH_REGISTER_COMMAND(calibrate, "stereo calibration from chessboard image pairs", RunCalibrate);

}  // namespace sh::tools
