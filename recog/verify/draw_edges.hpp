// Overlay drawing: the visible edges of a posed model, as one-pixel lines (Bresenham) through
// the projected samples, so the picture shows exactly what verification compared.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/image/image.hpp"
#include "recog/verify/view_camera.hpp"
#include "recog/verify/visible_edges.hpp"

namespace sh {

// Draws the visible runs of `visible` (computed for `camera`) into the image, which must have
// the camera's size. Lines leaving the image are clipped pixel by pixel.
Status DrawVisibleEdges(const ViewCamera& camera, const VisibleEdgeSet& visible, GrayView image,
                        uint8_t value);
Status DrawVisibleEdges(const ViewCamera& camera, const VisibleEdgeSet& visible,
                        ImageView<Rgb8> image, Rgb8 colour);

// Computes the visible edges of `object` (hidden by itself and by `occluders`) and draws them.
Status DrawPosedModel(const ViewCamera& camera, const PosedModel& object,
                      const PosedModel* occluders, size_t n_occluders, GrayView image,
                      uint8_t value);
Status DrawPosedModel(const ViewCamera& camera, const PosedModel& object,
                      const PosedModel* occluders, size_t n_occluders, ImageView<Rgb8> image,
                      Rgb8 colour);

}  // namespace sh
