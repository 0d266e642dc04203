#include "recog/image/noise.hpp"

#include <cstdint>
#include <cstdlib>

namespace sh {
namespace {

// |N * I| of 8-bit images lies in 0 .. 16 x 255; responses beyond the histogram's range (strong
// edges) all fall in its last bin, which the median of a mostly smooth image never reaches.
constexpr int kHistogramBins = 512;

// Half-normal median over standard deviation, and the operator's noise gain.
constexpr float kHalfNormalMedian = 0.6745f;
constexpr float kOperatorGain = 6.0f;

}  // namespace

NoiseEstimate EstimateNoise(const ConstGrayView& image) {
  NoiseEstimate out;
  if (image.empty() || image.width < 3 || image.height < 3) return out;
  uint32_t histogram[kHistogramBins] = {};
  size_t n = 0;
  for (int y = 1; y + 1 < image.height; y += 2) {
    const uint8_t* up = image.row(y - 1);
    const uint8_t* mid = image.row(y);
    const uint8_t* down = image.row(y + 1);
    for (int x = 1; x + 1 < image.width; x += 2) {
      const int r = (up[x - 1] + up[x + 1] + down[x - 1] + down[x + 1]) -
                    2 * (up[x] + down[x] + mid[x - 1] + mid[x + 1]) + 4 * mid[x];
      const int a = std::abs(r);
      ++histogram[a < kHistogramBins ? a : kHistogramBins - 1];
      ++n;
    }
  }
  // The median, interpolated inside its integer bin: responses of a low noise level take few
  // distinct values, and a bin's width would otherwise be a large step of the estimate.
  const size_t half = n / 2;
  size_t below = 0;
  int bin = 0;
  while (bin < kHistogramBins - 1 && below + histogram[bin] <= half) below += histogram[bin++];
  const float within = histogram[bin] ? (static_cast<float>(half - below) + 0.5f) /
                                            static_cast<float>(histogram[bin])
                                      : 0.5f;
  // Bin b holds |r| = b exactly; spreading it over [b - 0.5, b + 0.5) (bin 0 over [0, 0.5))
  // makes the median continuous in the noise level.
  const float median = bin == 0 ? 0.5f * within : static_cast<float>(bin) - 0.5f + within;
  out.samples = n;
  out.median_response = median;
  out.sigma = median / (kHalfNormalMedian * kOperatorGain);
  return out;
}

}  // namespace sh
