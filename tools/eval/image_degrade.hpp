// A camera made worse on purpose: defocus, exposure and sensor noise applied to a recorded image
// before recognition, so that a recorded set shows how much margin a camera setting leaves
// (`stereohash bench recorded --noise/--blur/--gain`).
//
// The order is the sensor's: the lens blurs the scene (Gaussian defocus), the exposure scales it
// (clipped at white), then the sensor adds its noise and the result is rounded to 8 bits. The
// noise is read noise plus shot noise, split so that `noise_sigma` is the total standard
// deviation at mid grey (128): variance(I) = sigma^2 (1/2 + I / 256). Dark pixels carry less
// noise than bright ones, as on a real sensor.
//
// Reproducible: every random value is a hash of (seed, channel, pixel), so the same seed gives the
// same bytes on every machine and standard library.
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"

namespace sh::tools {

struct ImageDegradation {
  float noise_sigma = 0.0f;    // grey levels at mid grey; 0 for none
  float blur_sigma_px = 0.0f;  // Gaussian defocus; 0 for none
  float gain = 1.0f;           // exposure factor, clipped at 255

  bool none() const { return noise_sigma == 0.0f && blur_sigma_px == 0.0f && gain == 1.0f; }
};

// Checks the ranges: noise 0..64 grey levels, blur 0 or 0.3..8 px, gain 0.05..20.
Status ValidateDegradation(const ImageDegradation& degradation);

// Degrades `pixels` (`channels` interleaved 8-bit channels, rows packed) in place. Each channel
// draws its own noise, as the colour sites of a sensor do.
Status DegradeImage(const ImageDegradation& degradation, uint64_t seed, int width, int height,
                    int channels, uint8_t* pixels);

// A seed for one image of a recorded set: a hash of the scene's name and the camera.
uint64_t DegradationSeed(const char* scene_name, int camera);

}  // namespace sh::tools
