// The two cameras of the stereo pair and posed models, all expressed from the left-camera frame,
// the frame in which the recogniser reports every pose.
#pragma once

#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/model/model.hpp"

namespace sh {

// One camera: its intrinsics and the transform from the left-camera frame into its own frame.
struct ViewCamera {
  CameraIntrinsics intrinsics;
  RigidTransform cam_T_left;  // identity for the left camera
};

inline ViewCamera LeftView(const StereoCalibration& calib) {
  return {calib.left, RigidTransform::Identity()};
}

// x_right = R x_left + T, so (R, T) is right_T_left directly.
inline ViewCamera RightView(const StereoCalibration& calib) {
  ViewCamera view;
  view.intrinsics = calib.right;
  view.cam_T_left.R = calib.right_R_left.cast<float>();
  view.cam_T_left.t_mm = calib.right_t_left_mm.cast<float>();
  return view;
}

// A model placed in the scene. `cam_T_model` maps model millimetres into the left-camera frame.
struct PosedModel {
  const Model* model = nullptr;
  RigidTransform cam_T_model;
};

}  // namespace sh
