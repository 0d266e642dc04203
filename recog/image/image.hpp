// Non-owning views of 2-D pixel buffers, and the capacities of the image path.
//
// Image memory is owned by whoever captured or rendered the frame (pre-allocated camera buffers,
// static buffers in the pipeline); recog/ only reads and writes through views.
#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>

namespace sh {

// Largest image the static buffers of the pipeline are sized for. Frames up to this size are
// processed; larger frames are refused with kOutOfRange. 1296 is half of the widest supported
// sensor, so that any sensor up to kMaxSensorWidth x kMaxSensorHeight binned 2 x 2 fits whole.
inline constexpr int kMaxImageWidth = 1296;
inline constexpr int kMaxImageHeight = 1024;
inline constexpr size_t kMaxImagePixels = size_t{kMaxImageWidth} * kMaxImageHeight;

// Largest camera image taken at all (a 5 MP machine-vision sensor). Images larger than a
// pipeline frame are binned (recog/image/binning.hpp) and their calibration scaled with them
// (recog/camera/binning.hpp) before recognition.
inline constexpr int kMaxSensorWidth = 2592;
inline constexpr int kMaxSensorHeight = 2048;
inline constexpr size_t kMaxSensorPixels = size_t{kMaxSensorWidth} * kMaxSensorHeight;

template <typename T>
struct ImageView {
  T* data = nullptr;
  int width = 0;
  int height = 0;
  int stride = 0;  // elements (not bytes) between the starts of consecutive rows

  bool empty() const { return data == nullptr || width <= 0 || height <= 0; }
  bool contains(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
  T& at(int x, int y) const {
    assert(contains(x, y));
    return data[static_cast<ptrdiff_t>(y) * stride + x];
  }
  T* row(int y) const { return data + static_cast<ptrdiff_t>(y) * stride; }
  operator ImageView<const T>() const { return {data, width, height, stride}; }  // NOLINT
};

using GrayView = ImageView<uint8_t>;
using ConstGrayView = ImageView<const uint8_t>;

// Interleaved 8-bit RGB pixel; an RGB buffer of width w is an ImageView<Rgb8> with stride in
// pixels.
struct Rgb8 {
  uint8_t r = 0, g = 0, b = 0;
};
static_assert(sizeof(Rgb8) == 3, "Rgb8 must match interleaved RGB memory");

// Bilinear sample of an 8-bit image at (x, y), which the caller keeps within [0, width - 1) x
// [0, height - 1) (no clamping: the inner loops of correlation and verification).
inline float SampleGrayInside(const ConstGrayView& img, float x, float y) {
  const int x0 = static_cast<int>(x);
  const int y0 = static_cast<int>(y);
  const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
  const uint8_t* r0 = img.row(y0) + x0;
  const uint8_t* r1 = img.row(y0 + 1) + x0;
  const float top = r0[0] + fx * static_cast<float>(r0[1] - r0[0]);
  const float bottom = r1[0] + fx * static_cast<float>(r1[1] - r1[0]);
  return top + fy * (bottom - top);
}

}  // namespace sh
