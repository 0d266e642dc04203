// The silhouette of a posed model in one camera: the union of its faces' projected polygons
// (corners projected with the lens distortion, edges straight between them), scan-converted at
// pixel centres into a mask over the silhouette's bounding box.
//
// The view database renders its views with it and the recogniser predicts the region a pose
// must give (centroid for the corrective iterations, pixels for verification), so both sides
// agree on what a silhouette is. A 48-gon cap's edges bow by far less than a pixel under the
// distortion of a calibrated lens, so straight projected edges are enough.
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/image/image.hpp"
#include "recog/verify/view_camera.hpp"

namespace sh {

struct SilhouetteMask {
  // Pixels [x0, x0 + width) x [y0, y0 + height) of the image; mask values 255 inside, 0
  // outside. Clipped to the image: the mask never covers pixels outside it.
  int x0 = 0, y0 = 0, width = 0, height = 0;
  uint32_t area_px = 0;
  float cx = 0, cy = 0;     // centroid of the inside pixels (pixel centres at integer coordinates)
  bool clipped = false;     // part of the silhouette lies outside the image
  uint8_t* mask = nullptr;  // row-major, stride = width (the scratch buffer)

  bool empty() const { return area_px == 0; }
  bool inside(int x, int y) const {
    return x >= x0 && y >= y0 && x < x0 + width && y < y0 + height &&
           mask[(y - y0) * width + (x - x0)] != 0;
  }
  ConstGrayView view() const { return {mask, width, height, width}; }
};

struct SilhouetteScratch {
  uint8_t mask[kMaxImagePixels];
  float corners_px[kMaxModelCorners][2];
};

// Errors: null model, a corner behind or in the plane of the camera (kOutOfRange), an invalid
// model record. A silhouette wholly outside the image is an ok, empty mask.
Status RasterizeSilhouette(const ViewCamera& camera, const PosedModel& object,
                           SilhouetteScratch& scratch, SilhouetteMask* out);

}  // namespace sh
