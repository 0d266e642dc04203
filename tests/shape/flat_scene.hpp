// Flat-shaded colour stereo pairs for the shape path's unit tests: posed models drawn face by
// face (far faces first) with Lambert shading of their MTL colour under one directional light,
// on a grey table, through the cameras' projection with distortion. Small and exact where the
// tests need it (each face's outline is its projected polygon); the ray-traced renderer is for
// the benches.
#pragma once

#include <vector>

#include "recog/camera/camera_model.hpp"
#include "recog/image/frame.hpp"
#include "recog/verify/view_camera.hpp"

namespace sh::testing {

struct FlatPart {
  PosedModel posed;  // cam_T_model: model -> left camera
  float kd[3];       // linear 0..1
};

struct FlatImage {
  int width = 0, height = 0;
  std::vector<Rgb8> rgb;
  FrameView frame() const { return FrameView::Rgb({rgb.data(), width, height, width}); }
};

// The thesis-like stereo rig of the recorded sets: 756 x 581, f 1136.4 px, 120 mm baseline,
// converging by about 15 degrees.
StereoCalibration ThesisRig();

// Renders `parts` into both cameras; `table_grey` is the background's grey level, `noise` the
// standard deviation of per-pixel Gaussian noise (seeded, deterministic).
void RenderFlatPair(const StereoCalibration& calib, const std::vector<FlatPart>& parts,
                    uint8_t table_grey, float noise, FlatImage* left, FlatImage* right);

}  // namespace sh::testing
