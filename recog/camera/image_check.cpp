#include "recog/camera/image_check.hpp"

namespace sh {

Status CheckImageFitsCamera(const ConstGrayView& image, const CameraIntrinsics& cam,
                            const char* which) {
  if (image.empty()) {
    return Status::Error(StatusCode::kInvalidArgument, "%s image is empty", which);
  }
  if (image.width != cam.width || image.height != cam.height) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s image is %dx%d but the calibration says %dx%d", which, image.width,
                         image.height, cam.width, cam.height);
  }
  if (image.stride < image.width) {
    return Status::Error(StatusCode::kInvalidArgument, "%s image stride %d < width %d", which,
                         image.stride, image.width);
  }
  return Status::Ok();
}

}  // namespace sh
