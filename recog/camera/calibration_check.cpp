#include "recog/camera/calibration_check.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "recog/image/image.hpp"

namespace sh {

Status ValidateIntrinsics(const CameraIntrinsics& cam, const char* name, ImageBounds bounds) {
  if (cam.width <= 0 || cam.height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s camera: image size %dx%d must be positive", name, cam.width,
                         cam.height);
  }
  if (cam.width > bounds.max_width || cam.height > bounds.max_height) {
    return Status::Error(StatusCode::kOutOfRange,
                         "%s camera: image size %dx%d exceeds the supported %dx%d", name, cam.width,
                         cam.height, bounds.max_width, bounds.max_height);
  }
  const double all[] = {cam.fx, cam.fy, cam.cx, cam.cy, cam.k1, cam.k2, cam.p1, cam.p2, cam.k3};
  for (double v : all) {
    if (!std::isfinite(v)) {
      return Status::Error(StatusCode::kInvalidArgument, "%s camera: non-finite intrinsic value",
                           name);
    }
  }
  if (!(cam.fx > 0.0) || !(cam.fy > 0.0)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s camera: focal length fx=%g fy=%g must be positive", name, cam.fx,
                         cam.fy);
  }
  return Status::Ok();
}

namespace {

constexpr double kPi = 3.14159265358979323846;

double FieldOfViewDeg(double pixels, double focal_px) {
  return 2.0 * std::atan(0.5 * pixels / focal_px) * 180.0 / kPi;
}

// The radial part of the distortion, r_d = r * (1 + k1 r^2 + k2 r^4 + k3 r^6), over undistorted
// normalised radii r. Walks r outwards until r_d covers `reach` (the distorted radius of the
// farthest image corner): the mapping must increase all the way (else two rays meet in one
// pixel and undistortion has no unique answer) and its factor r_d / r stay within range.
Status CheckRadialMapping(const CameraIntrinsics& cam, double reach, const char* name) {
  constexpr int kSteps = 4096;
  constexpr double kMaxRadius = 8.0;  // 83 degrees off axis: past the corners of the widest view
  double last_rd = 0.0;
  for (int i = 1; i <= kSteps; ++i) {
    const double r = kMaxRadius * i / kSteps;
    const double r2 = r * r;
    const double factor = 1.0 + r2 * (cam.k1 + r2 * (cam.k2 + r2 * cam.k3));
    const double rd = r * factor;
    if (!(rd > last_rd)) {
      return Status::Error(StatusCode::kOutOfRange,
                           // Kept within Status::kMaxMessage for the widest numbers.
                           "%s camera: distortion k1=%g k2=%g k3=%g folds the image: radii turn "
                           "back at %.0f px, the corners are at %.0f px",
                           name, cam.k1, cam.k2, cam.k3, last_rd * cam.fx, reach * cam.fx);
    }
    if (factor < kMinRadialScale || factor > kMaxRadialScale) {
      return Status::Error(StatusCode::kOutOfRange,
                           "%s camera: distortion k1=%g k2=%g k3=%g scales radii by %.3g at %.0f "
                           "px from the principal point; plausible: %.1f..%.1f",
                           name, cam.k1, cam.k2, cam.k3, factor, rd * cam.fx, kMinRadialScale,
                           kMaxRadialScale);
    }
    if (rd >= reach) return Status::Ok();
    last_rd = rd;
  }
  return Status::Error(StatusCode::kOutOfRange,
                       "%s camera: distortion k1=%g k2=%g k3=%g does not reach the image corners",
                       name, cam.k1, cam.k2, cam.k3);
}

}  // namespace

Status CheckPlausibleIntrinsics(const CameraIntrinsics& cam, const char* name) {
  const double fov_x = FieldOfViewDeg(cam.width, cam.fx);
  const double fov_y = FieldOfViewDeg(cam.height, cam.fy);
  if (fov_x < kMinFieldOfViewDeg || fov_x > kMaxFieldOfViewDeg || fov_y < kMinFieldOfViewDeg ||
      fov_y > kMaxFieldOfViewDeg) {
    const bool x = fov_x < kMinFieldOfViewDeg || fov_x > kMaxFieldOfViewDeg;
    return Status::Error(StatusCode::kOutOfRange,
                         "%s camera: focal length %s = %g px gives a %.3g degree field of view "
                         "over %d px; plausible: %.0f..%.0f degrees",
                         name, x ? "fx" : "fy", x ? cam.fx : cam.fy, x ? fov_x : fov_y,
                         x ? cam.width : cam.height, kMinFieldOfViewDeg, kMaxFieldOfViewDeg);
  }
  if (cam.fx > kMaxFocalAspect * cam.fy || cam.fy > kMaxFocalAspect * cam.fx) {
    return Status::Error(StatusCode::kOutOfRange,
                         "%s camera: fx = %g px and fy = %g px differ by more than a factor %.0f",
                         name, cam.fx, cam.fy, kMaxFocalAspect);
  }
  if (cam.cx < 0.0 || cam.cx > cam.width || cam.cy < 0.0 || cam.cy > cam.height) {
    return Status::Error(StatusCode::kOutOfRange,
                         "%s camera: principal point (%g, %g) px lies outside the %d x %d image",
                         name, cam.cx, cam.cy, cam.width, cam.height);
  }
  if (std::fabs(cam.p1) > kMaxTangential || std::fabs(cam.p2) > kMaxTangential) {
    return Status::Error(StatusCode::kOutOfRange,
                         "%s camera: tangential distortion p1=%g p2=%g; plausible: |p| <= %g", name,
                         cam.p1, cam.p2, kMaxTangential);
  }
  // Distorted normalised radius of the farthest corner (both axes scaled to fx).
  const double dx = std::max(cam.cx, cam.width - cam.cx) / cam.fx;
  const double dy = std::max(cam.cy, cam.height - cam.cy) / cam.fy;
  return CheckRadialMapping(cam, std::sqrt(dx * dx + dy * dy), name);
}

Status ValidateRotation(const Eigen::Matrix3d& R, const char* name) {
  if (!R.allFinite()) {
    return Status::Error(StatusCode::kInvalidArgument, "%s: non-finite rotation entry", name);
  }
  const double orthonormality_error =
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthonormality_error > kRotationTolerance) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s is not a rotation: |R^T R - I| = %.3g exceeds %.0e", name,
                         orthonormality_error, kRotationTolerance);
  }
  const double det = R.determinant();
  if (std::fabs(det - 1.0) > kRotationTolerance) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s is not a rotation: det = %.6f (a reflection if -1)", name, det);
  }
  return Status::Ok();
}

Status ValidateStereoCalibration(const StereoCalibration& calib, ImageBounds bounds) {
  SH_RETURN_IF_ERROR(ValidateIntrinsics(calib.left, "left", bounds));
  SH_RETURN_IF_ERROR(ValidateIntrinsics(calib.right, "right", bounds));
  SH_RETURN_IF_ERROR(ValidateRotation(calib.right_R_left, "R"));
  if (!calib.right_t_left_mm.allFinite()) {
    return Status::Error(StatusCode::kInvalidArgument, "T: non-finite translation entry");
  }
  const double baseline_mm = calib.right_t_left_mm.norm();
  if (!(baseline_mm > 0.0)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "T is zero: the two cameras coincide, no stereo baseline");
  }
  if (baseline_mm < kMinBaselineMm || baseline_mm > kMaxBaselineMm) {
    return Status::Error(StatusCode::kOutOfRange,
                         "T: stereo baseline %.4g mm; plausible: %.0f..%.0f mm (T is in "
                         "millimetres)",
                         baseline_mm, kMinBaselineMm, kMaxBaselineMm);
  }
  SH_RETURN_IF_ERROR(CheckPlausibleIntrinsics(calib.left, "left"));
  return CheckPlausibleIntrinsics(calib.right, "right");
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& R) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  // Keep det +1: a reflection is refused before this is called, but guard anyway.
  if ((U * V.transpose()).determinant() < 0.0) U.col(2) = -U.col(2);
  return U * V.transpose();
}

}  // namespace sh
