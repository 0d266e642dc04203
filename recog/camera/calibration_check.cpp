#include "recog/camera/calibration_check.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>

#include "recog/image/image.hpp"

namespace sh {

Status ValidateIntrinsics(const CameraIntrinsics& cam, const char* name) {
  if (cam.width <= 0 || cam.height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s camera: image size %dx%d must be positive", name, cam.width,
                         cam.height);
  }
  if (cam.width > kMaxImageWidth || cam.height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange,
                         "%s camera: image size %dx%d exceeds the supported %dx%d", name, cam.width,
                         cam.height, kMaxImageWidth, kMaxImageHeight);
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

Status ValidateStereoCalibration(const StereoCalibration& calib) {
  SH_RETURN_IF_ERROR(ValidateIntrinsics(calib.left, "left"));
  SH_RETURN_IF_ERROR(ValidateIntrinsics(calib.right, "right"));
  SH_RETURN_IF_ERROR(ValidateRotation(calib.right_R_left, "R"));
  if (!calib.right_t_left_mm.allFinite()) {
    return Status::Error(StatusCode::kInvalidArgument, "T: non-finite translation entry");
  }
  if (!(calib.right_t_left_mm.norm() > 0.0)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "T is zero: the two cameras coincide, no stereo baseline");
  }
  return Status::Ok();
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& R) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d V = svd.matrixV();
  // Keep det +1: a reflection is refused before this is called, but guard anyway.
  if ((U * V.transpose()).determinant() < 0.0) U.col(2) = -U.col(2);
  return U * V.transpose();
}

}  // namespace sh
