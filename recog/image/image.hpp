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
// processed; larger frames are refused with kOutOfRange.
inline constexpr int kMaxImageWidth = 1280;
inline constexpr int kMaxImageHeight = 1024;
inline constexpr size_t kMaxImagePixels = size_t{kMaxImageWidth} * kMaxImageHeight;

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

}  // namespace sh
