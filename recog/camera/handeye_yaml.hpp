// The hand-eye calibration: where the stereo camera is in the robot's frame, as written by
// `stereohash calibrate-handeye` and read by the firmware for output_frame = robot.
//
//   %YAML:1.0
//   ---
//   eye_in_hand: 0                   # 0: cameras fixed in the cell, the frame is the robot base
//                                    # 1: cameras on the flange, the frame is the robot flange
//   R_robot_camera: !!opencv-matrix  # 3x3 rotation, row-major
//   t_robot_camera: !!opencv-matrix  # 3x1, millimetres
//   poses: 12                        # informational: robot poses used
//   residuals_mm_deg: !!opencv-matrix  # informational: rms and max position (mm), rotation (deg)
//
// x_robot = R_robot_camera x_left + t_robot_camera, x_left in the left camera frame (OpenCV
// axes). Same reader rules as the calibration file (opencv_yaml.hpp): strict, bounded, no
// allocation, errors name the line.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh {

inline constexpr size_t kMaxHandEyeYamlBytes = size_t{16} * 1024;
// A robot cell is not larger than this: a camera farther from the robot frame's origin is a
// unit mistake (metres written as millimetres) or a corrupted number.
inline constexpr double kMaxHandEyeDistanceMm = 20000.0;

struct HandEye {
  bool eye_in_hand = false;
  RigidTransform robot_T_camera;  // robot base (eye-to-hand) or flange (eye-in-hand) <- camera
  int poses = 0;                  // robot poses the calibration used (0 if not given)
  double residual_rms_mm = 0, residual_max_mm = 0, residual_rms_deg = 0, residual_max_deg = 0;
};

Result<HandEye> ParseHandEyeYaml(const char* text, size_t length);
// Writes `hand_eye` in the format above into out[0..capacity) NUL terminated; returns the length.
Result<size_t> WriteHandEyeYaml(const HandEye& hand_eye, char* out, size_t capacity);

}  // namespace sh
