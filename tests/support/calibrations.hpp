// The calibrations of the tests: one fixed rig and two families of random ones.
#pragma once

#include <random>

#include "recog/camera/camera_model.hpp"

namespace sh::testing {

// 756 x 581 pixels, f = 800 px, moderate barrel distortion; right camera 100 mm to the right,
// turned to converge on a point 500 mm in front of the left camera.
StereoCalibration TestCalibration();

// A converging rig like the thesis setup: 1280 x 1024 cameras, 120 mm baseline (plus random
// perturbation), looking at a table about 700 mm away; distortion scaled by `distortion`.
StereoCalibration RandomRig(std::mt19937& rng, double distortion);

// Any plausible calibration (width x height, every distortion term set, right camera about
// 120 mm to the side at a random small rotation): for file formats, which must carry every
// value.
StereoCalibration RandomCalibration(std::mt19937& rng, int width = 1280, int height = 1024);

}  // namespace sh::testing
