// Plausibility checks for a stereo calibration, shared by the file reader and writer, so that a
// calibration that would break projection or triangulation is refused where it enters.
#pragma once

#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"

namespace sh {

// Largest deviation of R^T R from the identity (element-wise) and of det R from +1 accepted for
// a rotation. OpenCV writes 16 significant digits (errors ~1e-15); 1e-5 still admits matrices
// typed in by hand with 6 decimals.
inline constexpr double kRotationTolerance = 1e-5;

// Checks one camera: image size within 1..kMaxImageWidth x 1..kMaxImageHeight, finite positive
// focal lengths, finite principal point and distortion. `name` ("left", "right") goes into the
// message.
Status ValidateIntrinsics(const CameraIntrinsics& cam, const char* name);

// Checks a rotation: finite, orthonormal within kRotationTolerance, det +1 (not a reflection).
Status ValidateRotation(const Eigen::Matrix3d& R, const char* name);

// Checks both cameras, the rotation, and a finite non-zero baseline.
Status ValidateStereoCalibration(const StereoCalibration& calib);

// Nearest rotation to an almost-orthonormal R (polar decomposition through the SVD), so that
// R^T is exactly its inverse for the geometry downstream.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& R);

}  // namespace sh
