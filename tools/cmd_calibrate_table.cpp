// `stereohash calibrate-table`: the pose of the table in the left camera, measured once from one
// stereo pair of a chessboard lying flat on it, written as table.yaml
// (recog/camera/table_yaml.hpp). Host only, uses OpenCV to find the board.
//
// The board's inner corners are found in both images, triangulated with the stereo calibration
// (distortion kept, as the recogniser does), and the board's grid is fitted to them by a rigid
// least-squares fit (Umeyama without scale). The table frame is the board's: origin at the
// first inner corner, x along the board's rows, z up towards the cameras, table top at z = 0.
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "recog/camera/table_yaml.hpp"
#include "recog/image/image.hpp"
#include "recog/stereo/triangulation.hpp"
#include "tools/board_detection.hpp"
#include "tools/chessboard.hpp"
#include "tools/command.hpp"
#include "tools/cv_commands.hpp"
#include "tools/recognize_setup.hpp"
#include "tools/report_util.hpp"

namespace sh::tools {
namespace {

void PrintHelp() {
  std::printf(
      "usage: stereohash calibrate-table --calib CALIB.yaml --left L.png --right R.png\n"
      "                                  --board <cols>x<rows> --square-mm S --out table.yaml\n"
      "Measures the pose of the table from one stereo pair of a chessboard lying flat on it and\n"
      "writes table.yaml (R_table, t_table: x_left = R_table x_table + t_table; table frame: "
      "origin\n"
      "at the board's first inner corner, x along its rows, z up towards the cameras).\n"
      "  --board      inner corners per row x per column, e.g. 9x6\n"
      "  --square-mm  chessboard square size in millimetres\n"
      "Prints the fit residuals (mm): the board's flatness and the stereo accuracy.\n");
}

int Fail(const char* what, const char* detail) {
  std::fprintf(stderr, "stereohash calibrate-table: %s%s\n", what, detail);
  return 1;
}

int CalibrateTable(const char* calib_path, const char* left_path, const char* right_path,
                   cv::Size board, double square_mm, const char* out_path) {
  const Result<StereoCalibration> calib = LoadCalibration(calib_path);
  if (!calib.ok()) return Fail("", calib.status().message());
  // Read and searched within a time and memory limit, as calibrate does.
  DetectionLimits limits;
  limits.max_width = kMaxSensorWidth;
  limits.max_height = kMaxSensorHeight;
  const PairDetection found = DetectBoardPair(left_path, right_path, board, limits);
  if (found.outcome != PairDetection::Outcome::kFound) return Fail("", found.message.c_str());
  if (found.image_size.width != calib->left.width ||
      found.image_size.height != calib->left.height ||
      found.image_size.width != calib->right.width ||
      found.image_size.height != calib->right.height) {
    return Fail("the images' size differs from the calibration's: ", calib_path);
  }
  const std::vector<cv::Point2f>& lc = found.left;
  const std::vector<cv::Point2f>& rc = found.right;

  // Triangulated corners (left camera) against the board grid (table frame, z = 0). OpenCV
  // orders the corners row by row in both images the same way for a board that is not
  // symmetric under a half turn (cols and rows of different parity); for a symmetric one the
  // order may flip between the images, which the residual check below catches.
  const int n = board.width * board.height;
  Eigen::Matrix3Xd grid(3, n), seen(3, n);
  std::vector<float> ray_gap(n);
  for (int i = 0; i < n; ++i) {
    RayMidpoint m;
    if (!TriangulatePixels(*calib, Eigen::Vector2d(lc[i].x, lc[i].y),
                           Eigen::Vector2d(rc[i].x, rc[i].y), &m)) {
      return Fail("a corner's rays are parallel: is the calibration right for these images? ",
                  calib_path);
    }
    seen.col(i) = m.p_mm;
    ray_gap[i] = static_cast<float>(m.gap_mm);
    const int row = i / board.width, column = i % board.width;  // corner i of the board
    grid.col(i) = Eigen::Vector3d(column * square_mm, row * square_mm, 0);
  }
  const Eigen::Matrix4d fit = Eigen::umeyama(grid, seen, /*with_scaling=*/false);
  Eigen::Matrix3d R = fit.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = fit.topRightCorner<3, 1>();
  std::vector<float> residual(n), height(n);
  for (int i = 0; i < n; ++i) {
    residual[i] = static_cast<float>((R * grid.col(i) + t - seen.col(i)).norm());
    height[i] = static_cast<float>(std::fabs(R.col(2).dot(seen.col(i) - t)));
  }
  // Table z up, towards the cameras: if the board's z points away, turn the frame half a turn
  // about its x axis (y and z change sign; the board's corners stay at z = 0).
  if (R.col(2).dot(t) > 0) {
    R.col(1) = -R.col(1);
    R.col(2) = -R.col(2);
  }
  RigidTransform left_T_table;
  left_T_table.R = R.cast<float>();
  left_T_table.t_mm = t.cast<float>();
  const float median_gap = Median(ray_gap);
  std::printf(
      "board %dx%d, %d corners: fit residual median %.2f mm, worst %.2f mm; flatness (distance "
      "from the fitted plane) worst %.2f mm; ray gap median %.2f mm\n",
      board.width, board.height, n, Median(residual), Max(residual), Max(height), median_gap);
  // A wrong correspondence (mirrored order), a wrong square size or a wrong calibration shows as
  // residuals of a large fraction of a square.
  if (Max(residual) > 0.25 * square_mm) {
    return Fail(
        "the board does not fit its grid (residual above a quarter square): check "
        "--square-mm, --board and the calibration",
        "");
  }
  char text[4096];
  const Result<size_t> written = WriteTableYaml(left_T_table, text, sizeof(text));
  if (!written.ok()) return Fail("", written.status().message());
  if (!WriteTextFile(out_path, std::string(text, *written))) {
    return Fail("cannot write ", out_path);
  }
  const Eigen::Vector3f& o = left_T_table.t_mm;
  const Eigen::Vector3f up = left_T_table.R.col(2);
  std::printf("table origin (%.1f, %.1f, %.1f) mm, normal (%.3f, %.3f, %.3f) -> %s\n", o.x(), o.y(),
              o.z(), up.x(), up.y(), up.z(), out_path);
  return 0;
}

int RunCalibrateTable(int argc, char** argv) {
  const char *calib = nullptr, *left = nullptr, *right = nullptr, *out = nullptr;
  cv::Size board;
  double square_mm = 0;
  for (int i = 1; i < argc; ++i) {
    const char *arg = nullptr, *value = nullptr;
    int exit_code = 0;
    if (!NextOption("calibrate-table", argc, argv, PrintHelp, &i, &arg, &value, &exit_code)) {
      return exit_code;
    }
    if (std::strcmp(arg, "--calib") == 0) {
      calib = value;
    } else if (std::strcmp(arg, "--left") == 0) {
      left = value;
    } else if (std::strcmp(arg, "--right") == 0) {
      right = value;
    } else if (std::strcmp(arg, "--out") == 0) {
      out = value;
    } else if (std::strcmp(arg, "--board") == 0) {
      if (!ParseBoardSize(value, &board)) {
        std::fprintf(stderr, "stereohash calibrate-table: --board wants <cols>x<rows>, e.g. 9x6\n");
        return 2;
      }
    } else if (std::strcmp(arg, "--square-mm") == 0) {
      if (!ParseSquareMm(value, &square_mm)) {
        std::fprintf(stderr,
                     "stereohash calibrate-table: --square-mm wants a size in millimetres, "
                     "%g..%g, not '%s'\n",
                     kMinSquareMm, kMaxSquareMm, value);
        return 2;
      }
    } else {
      std::fprintf(stderr, "stereohash calibrate-table: unknown option %s (see --help)\n", arg);
      return 2;
    }
  }
  if (!calib || !left || !right || !out || board.width == 0 || square_mm == 0) {
    std::fprintf(stderr,
                 "stereohash calibrate-table: --calib, --left, --right, --board, --square-mm and "
                 "--out are required (see --help)\n");
    return 2;
  }
  try {
    return CalibrateTable(calib, left, right, board, square_mm, out);
  } catch (const cv::Exception& e) {
    std::fprintf(stderr, "stereohash calibrate-table: OpenCV failed: %s\n", e.what());
    return 1;
  }
}

}  // namespace

// Registered by hand: the command's name has a dash, which the macro's identifier cannot.
static const CommandRegistrar kCalibrateTableCommand({"calibrate-table", kCalibrateTableSummary,
                                                      RunCalibrateTable});

}  // namespace sh::tools
