// The sensor noise of one grey image, estimated from the image itself, so that detector
// thresholds can follow the camera, its gain and the lighting instead of a preset.
//
// Immerkaer's operator N = [1 -2 1; -2 4 -2; 1 -2 1] (the difference of two Laplacians) cancels
// every linear intensity ramp, so on smooth surfaces it sees only the noise: for white noise of
// standard deviation sigma its response has standard deviation 6 sigma (the root of the sum of
// the squared weights, 36). Edges and corners respond too, but they cover a small part of the
// image, so the median of |N * I| (half-normal: median = 0.6745 x std) estimates the noise
// robustly where the mean would not.
#pragma once

#include "recog/image/image.hpp"

namespace sh {

struct NoiseEstimate {
  float sigma = 0.0f;         // grey levels; 0 for a noise-free (rendered, synthetic) image
  size_t samples = 0;         // pixels the median was taken over
  float median_response = 0;  // median |N * I|, grey levels
};

// Every second row and column of the interior (a quarter of the pixels): the median of a
// smooth image needs no more. Images smaller than 3 x 3 give sigma 0 and no samples.
NoiseEstimate EstimateNoise(const ConstGrayView& image);

}  // namespace sh
