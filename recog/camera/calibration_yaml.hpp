// Stereo calibration files in the YAML dialect of OpenCV's FileStorage.
//
// The file holds what OpenCV's stereo calibration produces:
//
//   %YAML:1.0
//   ---
//   image_width: 640            # one size for both cameras
//   image_height: 480
//   K1: !!opencv-matrix         # or M1; 3x3, no skew, last row 0 0 1
//      rows: 3
//      cols: 3
//      dt: d                    # d or f
//      data: [ fx, 0., cx, 0., fy, cy, 0., 0., 1. ]   # may continue on following lines
//   D1: !!opencv-matrix         # 1xN or Nx1: k1 k2 p1 p2 [k3]
//   K2 / M2, D2                 # right camera
//   R: !!opencv-matrix          # 3x3 rotation, x_right = R x_left + T
//   T: !!opencv-matrix          # 3x1 or 1x3, millimetres
//
// Other top-level keys (E, F, R1, P1, Q, rms, ...) are skipped. Distortion with 8, 12 or 14
// coefficients (rational, thin-prism, tilted models) is accepted only when every coefficient
// beyond k3 is zero, since the camera model has no place for them; otherwise it is refused.
//
// The parser is strict and bounded: it reads from the caller's buffer (at most
// kMaxCalibrationYamlBytes, need not be NUL-terminated), allocates nothing, and reports the first
// problem with its line number. Numbers are read with strtod, so the C locale is assumed.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"

namespace sh {

// Largest calibration file accepted; OpenCV's own output for a stereo pair is about 3 KiB.
inline constexpr size_t kMaxCalibrationYamlBytes = size_t{64} * 1024;

// Parses and validates (see calibration_check.hpp) a calibration file. R is replaced by the
// nearest exact rotation after it passed the orthonormality check.
Result<StereoCalibration> ParseCalibrationYaml(const char* text, size_t length);

// Writes `calib` in the format above (K1 D1 K2 D2 R T, 5 distortion coefficients, dt d, 17
// significant digits so that parsing gives back the same doubles) into out[0..capacity), NUL
// terminated. Returns the length written (without the NUL). Refuses an invalid calibration, left
// and right image sizes that differ, and a buffer that is too small (kResourceExhausted).
Result<size_t> WriteCalibrationYaml(const StereoCalibration& calib, char* out, size_t capacity);

}  // namespace sh
