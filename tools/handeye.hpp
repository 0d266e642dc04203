// Hand-eye calibration of the stereo camera against a robot (host only, OpenCV):
//
//   eye-to-hand  cameras fixed in the cell, a chessboard on the robot's flange:
//                finds base_T_camera (and, as a by-product, flange_T_board);
//   eye-in-hand  cameras on the flange, the chessboard fixed in the cell:
//                finds flange_T_camera (and base_T_board).
//
// Input per station i: the flange pose the robot reports, base_T_flange_i, and the board's pose
// in the left camera, camera_T_board_i, measured from a stereo pair. The solution is OpenCV's
// calibrateHandEye (AX = XB); the residuals say how well every station agrees with it: the
// board's pose predicted through the chain against the measured one, in mm at the board's
// corners and in degrees.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::tools {

// How the rotation of a robot pose is written in the CSV (after x y z in mm):
//   quat    w x y z (unit quaternion; ABB)
//   rotvec  rx ry rz in degrees (axis times angle; Universal Robots, with the angle in degrees)
//   zyx     A B C in degrees, R = Rz(A) Ry(B) Rx(C) (KUKA A B C; Fanuc W P R as C B A)
enum class RotationFormat { kQuaternion, kRotationVector, kZyxEuler };
bool ParseRotationFormat(const char* text, RotationFormat* format);

// Robot poses from CSV text: one per line, numbers separated by commas, semicolons, spaces or
// tabs; empty lines, '#' comments and a header line without numbers are skipped. Errors name the
// line.
Result<std::vector<RigidTransform>> ParseRobotPoses(const std::string& text, RotationFormat format);

// The board's pose in the left camera from its inner corners in both images (OpenCV order, the
// grid at z = 0 with the first corner at the origin): triangulated with the calibration and
// fitted rigidly. fit_max_mm receives the largest corner residual of the fit.
Result<RigidTransform> BoardPoseFromStereo(const StereoCalibration& calib,
                                           const std::vector<cv::Point2f>& left,
                                           const std::vector<cv::Point2f>& right, cv::Size board,
                                           double square_mm, double* fit_max_mm);

struct HandEyeSolution {
  RigidTransform robot_T_camera;  // base_T_camera (eye-to-hand) or flange_T_camera (eye-in-hand)
  RigidTransform other;           // flange_T_board (eye-to-hand) or base_T_board (eye-in-hand)
  std::vector<double> residual_mm, residual_deg;  // per station
  double rms_mm = 0, max_mm = 0, rms_deg = 0, max_deg = 0;
};

// At least 3 stations with rotations about two different axes. `method` is one of OpenCV's
// HandEyeCalibrationMethod values. `board_extent_mm` sets where the position residual is
// measured: the worst of the board's four outer corners.
Result<HandEyeSolution> SolveHandEye(const std::vector<RigidTransform>& base_T_flange,
                                     const std::vector<RigidTransform>& camera_T_board,
                                     bool eye_in_hand, int method, double board_width_mm,
                                     double board_height_mm);

}  // namespace sh::tools
