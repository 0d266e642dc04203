// Edge pixels with their gradient orientation: the output of Canny, the input of the Hough
// transform and of verification.
#pragma once

#include <cstdint>

#include "recog/image/image.hpp"

namespace sh {

// `edge` is non-zero at edge pixels. `orientation` holds, at edge pixels, the gradient direction
// modulo 180 degrees quantised to 256 steps: angle_rad = orientation * pi / 256 with the angle
// measured from the +x axis towards +y (image rows grow downwards).
struct EdgeMapView {
  ImageView<uint8_t> edge;
  ImageView<uint8_t> orientation;
};

struct ConstEdgeMapView {
  ImageView<const uint8_t> edge;
  ImageView<const uint8_t> orientation;
};

}  // namespace sh
