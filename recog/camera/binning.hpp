// The calibration of a binned image. With OpenCV's convention (pixel centres at whole
// coordinates), binned pixel u' covers full pixels factor*u' .. factor*u' + factor - 1, whose
// centre is u = factor*u' + (factor - 1)/2; so u' = (u + 0.5)/factor - 0.5. Focal lengths divide
// by the factor, the principal point follows that mapping, and the distortion coefficients (of
// normalised coordinates) and the rig geometry are unchanged: exact, not an approximation.
#pragma once

#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"

namespace sh {

// One camera's intrinsics for its image binned by `factor` (>= 1; 1 returns `cam` unchanged).
CameraIntrinsics BinIntrinsics(const CameraIntrinsics& cam, int factor);
StereoCalibration BinCalibration(const StereoCalibration& calib, int factor);

// The calibration of the frames recognition sees: `calib` binned by BinFactorFor() of its image
// size, as DirectoryCamera, the libcamera HAL and the tools bin the images of a sensor larger
// than kMaxImageWidth x kMaxImageHeight. kOutOfRange beyond kMaxSensorWidth x kMaxSensorHeight.
Result<StereoCalibration> FrameCalibration(const StereoCalibration& calib);

}  // namespace sh
