// `stereohash calibrate-handeye`: where the stereo camera is in the robot's frame, from robot
// stations (flange poses in a CSV) and the matching stereo pairs of a chessboard, written as the
// hand-eye file the firmware reads for output_frame = robot (recog/camera/handeye_yaml.hpp).
// Host only (OpenCV: chessboard corners, calibrateHandEye).
#include <glob.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "recog/camera/handeye_yaml.hpp"
#include "tools/chessboard.hpp"
#include "tools/command.hpp"
#include "tools/cv_commands.hpp"
#include "tools/handeye.hpp"
#include "tools/recognize_setup.hpp"
#include "tools/report_util.hpp"

namespace sh::tools {
namespace {

void PrintHelp() {
  std::printf(
      "usage: stereohash calibrate-handeye --calib CALIB.yaml --poses ROBOT.csv\n"
      "           --left '<glob>' --right '<glob>' --board <cols>x<rows> --square-mm S\n"
      "           --eye-to-hand | --eye-in-hand  --out handeye.yaml\n"
      "           [--rotation quat|rotvec|zyx] [--method park|tsai|horaud|andreff|daniilidis]\n"
      "Measures the camera's pose in the robot's frame from N robot stations: line i of the CSV\n"
      "is the flange pose the robot reports at station i (x y z in mm, then the rotation), the\n"
      "i-th left and right image (each glob sorted by name) the chessboard seen there.\n"
      "  --eye-to-hand  cameras fixed in the cell, the board on the flange: the robot base frame\n"
      "  --eye-in-hand  cameras on the flange, the board fixed in the cell: the flange frame\n"
      "  --rotation     quat: w x y z (ABB); rotvec: rx ry rz in degrees (UR, in degrees);\n"
      "                 zyx: A B C in degrees, R = Rz(A) Ry(B) Rx(C) (KUKA; Fanuc W P R = C B A)\n"
      "                 (default quat)\n"
      "  --method       OpenCV's calibrateHandEye method (default park)\n"
      "Prints the residual of every station (the board's pose through the solved chain against\n"
      "the measured one: mm at the board's outer corners, degrees) and writes their rms and max\n"
      "into the file. Use 10 or more stations with rotations of 20 degrees or more about\n"
      "different axes.\n");
}

int Fail(const char* what, const char* detail = "") {
  std::fprintf(stderr, "stereohash calibrate-handeye: %s%s\n", what, detail);
  return 1;
}

std::vector<std::string> GlobSorted(const char* pattern) {
  std::vector<std::string> paths;
  glob_t g;
  if (::glob(pattern, 0, nullptr, &g) == 0) {
    for (size_t i = 0; i < g.gl_pathc; ++i) paths.emplace_back(g.gl_pathv[i]);  // sorted
  }
  globfree(&g);
  return paths;
}

bool ParseMethod(const char* text, int* method) {
  const struct {
    const char* name;
    int method;
  } methods[] = {{"tsai", cv::CALIB_HAND_EYE_TSAI},
                 {"park", cv::CALIB_HAND_EYE_PARK},
                 {"horaud", cv::CALIB_HAND_EYE_HORAUD},
                 {"andreff", cv::CALIB_HAND_EYE_ANDREFF},
                 {"daniilidis", cv::CALIB_HAND_EYE_DANIILIDIS}};
  for (const auto& m : methods) {
    if (std::strcmp(text, m.name) == 0) {
      *method = m.method;
      return true;
    }
  }
  return false;
}

struct Options {
  const char *calib = nullptr, *poses = nullptr, *left = nullptr, *right = nullptr, *out = nullptr;
  cv::Size board;
  double square_mm = 0;
  int eye_in_hand = -1;  // unset
  RotationFormat rotation = RotationFormat::kQuaternion;
  int method = cv::CALIB_HAND_EYE_PARK;
};

int Calibrate(const Options& o) {
  const Result<StereoCalibration> calib = LoadCalibration(o.calib);
  if (!calib.ok()) return Fail("", calib.status().message());
  std::ifstream csv(o.poses);
  if (!csv) return Fail("cannot read the robot poses ", o.poses);
  std::stringstream text;
  text << csv.rdbuf();
  const Result<std::vector<RigidTransform>> robot = ParseRobotPoses(text.str(), o.rotation);
  if (!robot.ok()) return Fail(o.poses, (std::string(": ") + robot.status().message()).c_str());
  const std::vector<std::string> left = GlobSorted(o.left), right = GlobSorted(o.right);
  if (left.size() != robot->size() || right.size() != robot->size()) {
    char what[160];
    std::snprintf(what, sizeof(what),
                  "%zu robot poses but %zu left and %zu right images: one pair per station",
                  robot->size(), left.size(), right.size());
    return Fail(what);
  }
  std::vector<RigidTransform> base_T_flange, camera_T_board;
  for (size_t i = 0; i < left.size(); ++i) {
    const cv::Mat l = cv::imread(left[i], cv::IMREAD_GRAYSCALE);
    const cv::Mat r = cv::imread(right[i], cv::IMREAD_GRAYSCALE);
    if (l.empty() || r.empty()) return Fail("cannot read ", (l.empty() ? left : right)[i].c_str());
    std::vector<cv::Point2f> lc, rc;
    if (!FindBoard(l, o.board, &lc) || !FindBoard(r, o.board, &rc)) {
      std::printf("station %2zu: board not found in both images, skipped (%s)\n", i,
                  left[i].c_str());
      continue;
    }
    double fit_max_mm = 0;
    const Result<RigidTransform> pose =
        BoardPoseFromStereo(*calib, lc, rc, o.board, o.square_mm, &fit_max_mm);
    if (!pose.ok())
      return Fail(left[i].c_str(), (std::string(": ") + pose.status().message()).c_str());
    if (fit_max_mm > 0.25 * o.square_mm) {
      std::printf("station %2zu: the board does not fit its grid (%.2f mm), skipped\n", i,
                  fit_max_mm);
      continue;
    }
    base_T_flange.push_back((*robot)[i]);
    camera_T_board.push_back(*pose);
  }
  const Result<HandEyeSolution> s =
      SolveHandEye(base_T_flange, camera_T_board, o.eye_in_hand == 1, o.method,
                   (o.board.width - 1) * o.square_mm, (o.board.height - 1) * o.square_mm);
  if (!s.ok()) return Fail("", s.status().message());
  for (size_t i = 0; i < s->residual_mm.size(); ++i) {
    std::printf("station %2zu: residual %.3f mm, %.3f deg\n", i, s->residual_mm[i],
                s->residual_deg[i]);
  }
  HandEye h;
  h.eye_in_hand = o.eye_in_hand == 1;
  h.robot_T_camera = s->robot_T_camera;
  h.poses = static_cast<int>(base_T_flange.size());
  h.residual_rms_mm = s->rms_mm;
  h.residual_max_mm = s->max_mm;
  h.residual_rms_deg = s->rms_deg;
  h.residual_max_deg = s->max_deg;
  char yaml[8192];
  const Result<size_t> n = WriteHandEyeYaml(h, yaml, sizeof(yaml));
  if (!n.ok()) return Fail("", n.status().message());
  if (!WriteTextFile(o.out, std::string(yaml, *n))) return Fail("cannot write ", o.out);
  const Eigen::AngleAxisf aa(h.robot_T_camera.R);
  const Eigen::Vector3f rv = aa.axis() * aa.angle() * 57.29577951f;  // radians to degrees
  const Eigen::Vector3f& t = h.robot_T_camera.t_mm;
  std::printf(
      "%zu stations: residual rms %.3f mm / %.3f deg, max %.3f mm / %.3f deg\n"
      "%s_T_camera: t = (%.2f, %.2f, %.2f) mm, rotation vector (%.3f, %.3f, %.3f) deg -> %s\n",
      base_T_flange.size(), s->rms_mm, s->rms_deg, s->max_mm, s->max_deg,
      h.eye_in_hand ? "flange" : "base", t.x(), t.y(), t.z(), rv.x(), rv.y(), rv.z(), o.out);
  return 0;
}

int RunCalibrateHandEye(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--eye-to-hand") == 0 || std::strcmp(argv[i], "--eye-in-hand") == 0) {
      o.eye_in_hand = argv[i][6] == 'i' ? 1 : 0;  // "--eye-in-hand"
      continue;
    }
    const char *arg = nullptr, *value = nullptr;
    int exit_code = 0;
    if (!NextOption("calibrate-handeye", argc, argv, PrintHelp, &i, &arg, &value, &exit_code)) {
      return exit_code;
    }
    bool ok = true;
    if (std::strcmp(arg, "--calib") == 0) {
      o.calib = value;
    } else if (std::strcmp(arg, "--poses") == 0) {
      o.poses = value;
    } else if (std::strcmp(arg, "--left") == 0) {
      o.left = value;
    } else if (std::strcmp(arg, "--right") == 0) {
      o.right = value;
    } else if (std::strcmp(arg, "--out") == 0) {
      o.out = value;
    } else if (std::strcmp(arg, "--board") == 0) {
      ok = ParseBoardSize(value, &o.board);
    } else if (std::strcmp(arg, "--square-mm") == 0) {
      ok = ParseSquareMm(value, &o.square_mm);
    } else if (std::strcmp(arg, "--rotation") == 0) {
      ok = ParseRotationFormat(value, &o.rotation);
    } else if (std::strcmp(arg, "--method") == 0) {
      ok = ParseMethod(value, &o.method);
    } else {
      ok = false;
    }
    if (!ok) {
      std::fprintf(stderr,
                   "stereohash calibrate-handeye: bad option or value: %s %s (see --help)\n", arg,
                   value);
      return 2;
    }
  }
  if (o.calib == nullptr || o.poses == nullptr || o.left == nullptr || o.right == nullptr ||
      o.out == nullptr || o.board.width == 0 || o.square_mm <= 0 || o.eye_in_hand < 0) {
    std::fprintf(stderr,
                 "stereohash calibrate-handeye: --calib, --poses, --left, --right, --board, "
                 "--square-mm, --out and --eye-to-hand or --eye-in-hand are required (see "
                 "--help)\n");
    return 2;
  }
  return Calibrate(o);
}

}  // namespace

// Registered by hand: the command's name has a dash, which the macro's identifier cannot.
static const CommandRegistrar kCalibrateHandEyeCommand({"calibrate-handeye",
                                                        kCalibrateHandEyeSummary,
                                                        RunCalibrateHandEye});

}  // namespace sh::tools
