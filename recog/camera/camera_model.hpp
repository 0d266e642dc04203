// Pinhole camera with OpenCV's radial-tangential lens distortion (k1 k2 p1 p2 k3), used directly
// on the distorted images: features are never rectified, rays are undistorted on demand.
//
// Frames: the left camera frame is the reference (x right, y down, z forward, millimetres).
// `x_right = R * x_left + T_mm` as written by OpenCV's stereoCalibrate.
#pragma once

#include <Eigen/Core>

namespace sh {

struct CameraIntrinsics {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;          // pixels
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;  // OpenCV distortion coefficients
};

struct StereoCalibration {
  CameraIntrinsics left;
  CameraIntrinsics right;
  Eigen::Matrix3d right_R_left = Eigen::Matrix3d::Identity();  // OpenCV's R
  Eigen::Vector3d right_t_left_mm = Eigen::Vector3d::Zero();   // OpenCV's T, in millimetres
};

// Applies the distortion model to normalised undistorted image coordinates (x/z, y/z).
Eigen::Vector2d Distort(const CameraIntrinsics& cam, const Eigen::Vector2d& xy_norm);

// Pixel of a point given in this camera's frame (z > 0 expected; returns false otherwise).
bool ProjectToPixel(const CameraIntrinsics& cam, const Eigen::Vector3d& x_cam_mm,
                    Eigen::Vector2d* pixel);

// Normalised undistorted coordinates (x/z, y/z) of a distorted pixel: OpenCV's fixed-point
// iteration as a start, then damped Newton steps; converged to ~1e-12 px wherever the distortion
// is invertible (radial factor increasing with the radius), which covers the image of any
// calibrated lens.
Eigen::Vector2d UndistortPixel(const CameraIntrinsics& cam, const Eigen::Vector2d& pixel);

// Unit viewing ray through a pixel, in this camera's frame.
Eigen::Vector3d PixelRay(const CameraIntrinsics& cam, const Eigen::Vector2d& pixel);

// Right camera centre and rotation expressed in the left frame.
Eigen::Vector3d RightCentreInLeft(const StereoCalibration& calib);

}  // namespace sh
