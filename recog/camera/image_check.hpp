// Whether an image can be the image of a calibrated camera: not empty, the calibration's size,
// rows at least as long as the width. Every pipeline (stereo, one camera) checks its frames so.
#pragma once

#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/image/image.hpp"

namespace sh {

// `which` names the image in the message ("left", "right").
Status CheckImageFitsCamera(const ConstGrayView& image, const CameraIntrinsics& cam,
                            const char* which);

}  // namespace sh
