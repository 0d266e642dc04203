#include "recog/camera/binning.hpp"

#include "recog/image/binning.hpp"

namespace sh {

CameraIntrinsics BinIntrinsics(const CameraIntrinsics& cam, int factor) {
  if (factor <= 1) return cam;
  const double f = factor;
  CameraIntrinsics out = cam;
  out.width = BinnedSize(cam.width, factor);
  out.height = BinnedSize(cam.height, factor);
  out.fx = cam.fx / f;
  out.fy = cam.fy / f;
  out.cx = (cam.cx + 0.5) / f - 0.5;
  out.cy = (cam.cy + 0.5) / f - 0.5;
  return out;
}

StereoCalibration BinCalibration(const StereoCalibration& calib, int factor) {
  StereoCalibration out = calib;
  out.left = BinIntrinsics(calib.left, factor);
  out.right = BinIntrinsics(calib.right, factor);
  return out;
}

Result<StereoCalibration> FrameCalibration(const StereoCalibration& calib) {
  const Result<int> factor = BinFactorFor(calib.left.width, calib.left.height);
  if (!factor.ok()) return factor.status().WithContext("calibration");
  return BinCalibration(calib, *factor);
}

}  // namespace sh
