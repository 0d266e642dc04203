// Binning: an image larger than the pipeline's frames (a 5 MP sensor) is reduced by an integer
// factor before recognition, each output pixel the mean of a factor x factor block. An integer
// factor keeps the geometry exact: the calibration scales with it (recog/camera/binning.hpp),
// principal point and distortion included, where a fractional resampling would blur and shift.
#pragma once

#include "recog/base/status.hpp"
#include "recog/image/image.hpp"

namespace sh {

// Largest binning factor: a sensor up to kMaxSensorWidth x kMaxSensorHeight needs 2.
inline constexpr int kMaxBinFactor = 4;

// The smallest factor 1..kMaxBinFactor that brings width x height within kMaxImageWidth x
// kMaxImageHeight; kOutOfRange naming the size when the image is larger than
// kMaxSensorWidth x kMaxSensorHeight or not positive.
Result<int> BinFactorFor(int width, int height);

// Size of an image binned by `factor`: the whole blocks (a remainder row or column is dropped).
inline int BinnedSize(int size, int factor) { return size / factor; }

// Writes the block means of `src` (rounded to nearest) into `dst`, which must be exactly
// BinnedSize(src.width, factor) x BinnedSize(src.height, factor) (else kInvalidArgument).
// No allocation; `src` and `dst` must not overlap.
Status BinGray(ConstGrayView src, int factor, GrayView dst);
Status BinRgb(ImageView<const Rgb8> src, int factor, ImageView<Rgb8> dst);

}  // namespace sh
