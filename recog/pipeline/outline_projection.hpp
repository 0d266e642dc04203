// What recognised objects look like in the images, for overlays drawn for a person (the board's
// live view, the recognise command's pictures): the visible edges of posed models, hidden lines
// removed, and straight 3-D segments, as polylines of distorted pixels in the full-size image.
// Not on the per-frame path: it allocates.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/verify/view_camera.hpp"

namespace sh {

// x, y pairs in pixels of the full-size image.
using PixelPolyline = std::vector<float>;

// The visible edges of each of the n posed models (poses in the left camera frame), the others
// as occluders (the kMaxOccluders first), in image `side` (0 left, 1 right): lines[k] for model
// k. A model whose edges cannot be computed gets none.
std::vector<std::vector<PixelPolyline>> VisibleOutlines(const StereoCalibration& calibration,
                                                        const PosedModel* posed, size_t n,
                                                        int side);

// Straight segments ends[2k]..ends[2k+1] (in the frame left_T_frame maps into the left camera)
// projected into image `side`: polylines cut where they leave the image or pass behind the
// camera.
std::vector<PixelPolyline> ProjectSegments(const StereoCalibration& calibration,
                                           const RigidTransform& left_T_frame,
                                           const std::vector<Eigen::Vector3f>& ends, int side);

}  // namespace sh
