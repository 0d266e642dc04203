// Plausibility checks for a stereo calibration, shared by the file reader and writer, so that a
// calibration that would break projection or triangulation is refused where it enters.
#pragma once

#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/image/image.hpp"

namespace sh {

// Largest deviation of R^T R from the identity (element-wise) and of det R from +1 accepted for
// a rotation. OpenCV writes 16 significant digits (errors ~1e-15); 1e-5 still admits matrices
// typed in by hand with 6 decimals.
inline constexpr double kRotationTolerance = 1e-5;

// The largest image size a check accepts: a pipeline frame, or a camera's full sensor (a
// calibration file, used on images binned to a frame; recog/camera/binning.hpp).
struct ImageBounds {
  int max_width;
  int max_height;
};
inline constexpr ImageBounds kFrameBounds{kMaxImageWidth, kMaxImageHeight};
inline constexpr ImageBounds kSensorBounds{kMaxSensorWidth, kMaxSensorHeight};

// Checks one camera: image size within 1..bounds, finite positive focal lengths, finite
// principal point and distortion. `name` ("left", "right") goes into the message.
Status ValidateIntrinsics(const CameraIntrinsics& cam, const char* name,
                          ImageBounds bounds = kFrameBounds);

// Checks a rotation: finite, orthonormal within kRotationTolerance, det +1 (not a reflection).
Status ValidateRotation(const Eigen::Matrix3d& R, const char* name);

// Plausibility limits: what a camera that images the scene at all can have. Values outside
// come from a failed calibration (inconsistent board views) or a typing error, and would make
// recognition report nothing rather than fail.
inline constexpr double kMinFieldOfViewDeg = 1.0;    // horizontal and vertical
inline constexpr double kMaxFieldOfViewDeg = 150.0;  // beyond: a fisheye, not this lens model
inline constexpr double kMaxFocalAspect = 2.0;       // fx / fy and fy / fx
inline constexpr double kMinRadialScale = 0.5;       // radial distortion factor anywhere in
inline constexpr double kMaxRadialScale = 2.0;       // the image (1 = no distortion)
inline constexpr double kMaxTangential = 0.1;        // |p1|, |p2|
inline constexpr double kMinBaselineMm = 5.0;
inline constexpr double kMaxBaselineMm = 1000.0;

// The lens of one camera is plausible for its image size: field of view within
// kMinFieldOfViewDeg..kMaxFieldOfViewDeg, pixel aspect within 1/kMaxFocalAspect..kMaxFocalAspect,
// principal point inside the image, and a distortion that maps the image one to one (radial
// mapping increasing out to the farthest image corner) with a radial factor within
// kMinRadialScale..kMaxRadialScale and |p1|, |p2| <= kMaxTangential. The message names the
// value and the plausible range. Expects ValidateIntrinsics() to have passed.
Status CheckPlausibleIntrinsics(const CameraIntrinsics& cam, const char* name);

// Checks both cameras and the rotation (ValidateIntrinsics, ValidateRotation), a finite baseline
// within kMinBaselineMm..kMaxBaselineMm, and the plausibility of both lenses.
Status ValidateStereoCalibration(const StereoCalibration& calib, ImageBounds bounds = kFrameBounds);

// Nearest rotation to an almost-orthonormal R (polar decomposition through the SVD), so that
// R^T is exactly its inverse for the geometry downstream.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& R);

}  // namespace sh
