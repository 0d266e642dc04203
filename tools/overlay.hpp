// Result overlays for the host tools: the left and right images side by side in colour, with the
// recognised models' visible edges drawn in distinct colours and labelled with the model name.
#pragma once

#include <cstdint>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "recog/verify/draw_edges.hpp"

namespace sh::tools {

// Draws `text` (lower-case letters, digits, space and - _ . # ( ) :) with a 5 x 7 pixel font
// enlarged `scale` times, its top-left corner at (x, y), with a one-pixel dark outline so that it
// reads on any background. Unknown characters draw as a box; pixels outside the image are
// skipped.
void DrawText(ImageView<Rgb8> image, int x, int y, const char* text, int scale, Rgb8 colour);

// Width in pixels of `text` drawn at `scale`.
int TextWidth(const char* text, int scale);

// Colour of the i-th object: well separated hues that stand out on grey.
Rgb8 ObjectColour(int i);

// Builds the side-by-side overlay (2 w x h RGB, packed rows) of posed models: each one's
// visible edges (hidden lines removed, the others as occluders) and its name.
Status BuildPosedOverlay(const StereoCalibration& calib, const PosedModel* posed, size_t n,
                         ConstGrayView left, ConstGrayView right, std::vector<uint8_t>* rgb,
                         int* width, int* height);

// The overlay of one processed frame of the pipeline.
Status BuildOverlay(const Pipeline& pipeline, const PipelineResult& result, ConstGrayView left,
                    ConstGrayView right, std::vector<uint8_t>* rgb, int* width, int* height);

// The detectors' output of one processed frame, left | right (2 w x h RGB, packed rows), for
// commissioning and diagnosis: edge pixels in blue, the supported segments of the Hough lines in
// yellow, corners as crosses, green when stereo paired them into a 3-D point, red otherwise.
Status BuildFeatureOverlay(const Pipeline& pipeline, ConstGrayView left, ConstGrayView right,
                           std::vector<uint8_t>* rgb, int* width, int* height);

// Draws a posed model's visible edges (hidden by `occluders`) into the left | right overlay of
// the calibration `calib`, labelled with `label` at the model's centre.
Status DrawLabelledModel(const StereoCalibration& calib, const PosedModel& posed,
                         const PosedModel* occluders, size_t n_occluders, const char* label,
                         Rgb8 colour, std::vector<uint8_t>* rgb, int width, int height);

}  // namespace sh::tools
