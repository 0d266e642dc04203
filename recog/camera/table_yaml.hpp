// The pose of the table (conveyor, work surface) in the left camera frame, as an installation
// measures it once, e.g. from a chessboard lying on the table (`stereohash calibrate-table`):
//
//   %YAML:1.0
//   ---
//   R_table: !!opencv-matrix     # 3x3 rotation, row-major
//      rows: 3
//      cols: 3
//      dt: d
//      data: [ ... ]
//   t_table: !!opencv-matrix     # 3x1 or 1x3, millimetres
//      rows: 3
//      cols: 1
//      dt: d
//      data: [ tx, ty, tz ]
//
// x_left = R_table x_table + t_table; the table frame has z up (towards the cameras) and the
// table top at z = 0. Other keys are skipped. Same reader rules as the calibration file
// (opencv_yaml.hpp): strict, bounded, no allocation, errors name the line.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh {

inline constexpr size_t kMaxTableYamlBytes = size_t{16} * 1024;

// Farthest table origin accepted from the left camera: beyond 100 m the file is not a table
// pose of a stereo cell (millimetres confused with micrometres, a corrupted number).
inline constexpr double kMaxTableDistanceMm = 100000.0;

// Parses and checks the table pose: R a rotation (orthonormal within kRotationTolerance, det +1,
// then replaced by the nearest exact rotation), t finite and within kMaxTableDistanceMm, and the
// table's front (+z) facing the camera (a table seen from below is a flipped axis).
Result<RigidTransform> ParseTableYaml(const char* text, size_t length);

// Writes the pose in the format above into out[0..capacity), NUL terminated; returns the length
// without the NUL. Refuses a pose the reader would refuse and a too small buffer.
Result<size_t> WriteTableYaml(const RigidTransform& left_T_table, char* out, size_t capacity);

}  // namespace sh
